// Server reflection as a generic client uses it (grpcurl, Postman): with nothing compiled in but
// the reflection protocol, the test asks brdfd over grpc.reflection.v1 which services it serves
// and for the file defining brdf.v1.Control, builds its own descriptor pool from the answers,
// and calls GetRigStatus with a message made from those descriptors alone. v1alpha answers the
// same; an unknown symbol gets NOT_FOUND quoting a short prefix of the name.
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>

#include <future>
#include <map>
#include <set>

#include "grpc/reflection/v1/reflection.grpc.pb.h"
#include "grpc/reflection/v1alpha/reflection.grpc.pb.h"
#include "tests/support/daemon/test_rig.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
namespace pb = google::protobuf;
namespace refl = grpc::reflection::v1;

class ReflectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Status st = rig_.StartSim();
    ASSERT_TRUE(st.ok()) << st.ToString();
    st = rig_.StartDaemon();
    ASSERT_TRUE(st.ok()) << st.ToString();
  }
  // One request on a fresh v1 stream; its answer.
  refl::ServerReflectionResponse Ask(const refl::ServerReflectionRequest& request) {
    auto stub = refl::ServerReflection::NewStub(rig_.channel());
    grpc::ClientContext context;  // no token: reflection is open
    context.set_deadline(std::chrono::system_clock::now() + 10s);
    auto stream = stub->ServerReflectionInfo(&context);
    EXPECT_TRUE(stream->Write(request));
    refl::ServerReflectionResponse response;
    EXPECT_TRUE(stream->Read(&response));
    stream->WritesDone();
    EXPECT_TRUE(stream->Finish().ok());
    return response;
  }
  DaemonRig rig_;
};

// Builds `name` and (first) what it imports into `pool`.
const pb::FileDescriptor* Build(const std::string& name,
                                const std::map<std::string, pb::FileDescriptorProto>& files,
                                pb::DescriptorPool* pool) {
  if (const pb::FileDescriptor* done = pool->FindFileByName(name)) return done;
  auto it = files.find(name);
  if (it == files.end()) return nullptr;
  for (const std::string& dep : it->second.dependency()) {
    if (Build(dep, files, pool) == nullptr) return nullptr;
  }
  return pool->BuildFile(it->second);
}

TEST_F(ReflectionTest, AGenericClientLearnsTheApiOverV1AndCallsIt) {
  refl::ServerReflectionRequest list;
  list.set_list_services("");
  const refl::ServerReflectionResponse listed = Ask(list);
  std::set<std::string> services;
  for (const auto& s : listed.list_services_response().service()) services.insert(s.name());
  for (const char* name :
       {"brdf.v1.Control", "brdf.v1.Data", "brdf.v1.Interpolation", "grpc.health.v1.Health",
        "grpc.reflection.v1.ServerReflection", "grpc.reflection.v1alpha.ServerReflection"}) {
    EXPECT_EQ(services.count(name), 1u) << name;
  }

  refl::ServerReflectionRequest symbol;
  symbol.set_file_containing_symbol("brdf.v1.Control");
  const refl::ServerReflectionResponse files = Ask(symbol);
  ASSERT_TRUE(files.has_file_descriptor_response()) << files.error_response().error_message();
  std::map<std::string, pb::FileDescriptorProto> protos;
  std::string first;
  for (const std::string& bytes : files.file_descriptor_response().file_descriptor_proto()) {
    pb::FileDescriptorProto proto;
    ASSERT_TRUE(proto.ParseFromString(bytes));
    if (first.empty()) first = proto.name();
    protos[proto.name()] = proto;
  }
  EXPECT_EQ(first, "brdf/v1/brdf.proto");  // the file asked for first, then its imports
  pb::DescriptorPool pool;  // not the test's own generated pool: only what reflection said
  ASSERT_NE(Build(first, protos, &pool), nullptr) << "the imports did not all come along";
  const pb::MethodDescriptor* method = pool.FindMethodByName("brdf.v1.Control.GetRigStatus");
  ASSERT_NE(method, nullptr);

  pb::DynamicMessageFactory factory(&pool);
  std::unique_ptr<pb::Message> request(factory.GetPrototype(method->input_type())->New());
  std::string wire;
  ASSERT_TRUE(request->SerializeToString(&wire));
  grpc::GenericStub generic(rig_.channel());
  auto context = DaemonRig::Context(kAnalystToken);
  grpc::Slice slice(wire);
  grpc::ByteBuffer out(&slice, 1), in;
  std::promise<grpc::Status> done;
  generic.UnaryCall(context.get(), "/brdf.v1.Control/GetRigStatus", grpc::StubOptions(), &out, &in,
                    [&done](grpc::Status st) { done.set_value(std::move(st)); });
  const grpc::Status st = done.get_future().get();
  ASSERT_TRUE(st.ok()) << st.error_message();
  std::vector<grpc::Slice> slices;
  ASSERT_TRUE(in.Dump(&slices).ok());
  std::string reply;
  for (const auto& s : slices) reply.append(reinterpret_cast<const char*>(s.begin()), s.size());
  std::unique_ptr<pb::Message> status(factory.GetPrototype(method->output_type())->New());
  ASSERT_TRUE(status->ParseFromString(reply));
  const pb::FieldDescriptor* devices = method->output_type()->FindFieldByName("devices");
  ASSERT_NE(devices, nullptr);
  EXPECT_EQ(status->GetReflection()->FieldSize(*status, devices), 2);  // meter and stage
}

TEST_F(ReflectionTest, V1AlphaAnswersTooAndUnknownSymbolsAreNamedShortly) {
  auto stub = grpc::reflection::v1alpha::ServerReflection::NewStub(rig_.channel());
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 10s);
  auto stream = stub->ServerReflectionInfo(&context);
  grpc::reflection::v1alpha::ServerReflectionRequest request;
  request.set_file_containing_symbol("brdf.v1.Data");
  ASSERT_TRUE(stream->Write(request));
  grpc::reflection::v1alpha::ServerReflectionResponse response;
  ASSERT_TRUE(stream->Read(&response));
  ASSERT_TRUE(response.has_file_descriptor_response());
  // Same stream: the file again (always the file asked for), its imports not resent.
  ASSERT_TRUE(stream->Write(request));
  ASSERT_TRUE(stream->Read(&response));
  EXPECT_EQ(response.file_descriptor_response().file_descriptor_proto_size(), 1);
  request.set_file_containing_symbol("no.such." + std::string(50000, 'X'));
  ASSERT_TRUE(stream->Write(request));
  ASSERT_TRUE(stream->Read(&response));
  ASSERT_TRUE(response.has_error_response());
  EXPECT_EQ(response.error_response().error_code(), static_cast<int>(grpc::StatusCode::NOT_FOUND));
  EXPECT_LT(response.error_response().error_message().size(), 300u);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

}  // namespace
}  // namespace brdf::testing
