#include "tests/support/daemon/raw_call.h"

#include <google/protobuf/dynamic_message.h>
#include <grpcpp/generic/generic_stub.h>

#include <sstream>

#include "brdf/v1/brdf.pb.h"
#include "tests/support/daemon/test_rig.h"

namespace brdf::testing {

using google::protobuf::MethodDescriptor;

std::vector<const MethodDescriptor*> AllMethods() {
  const google::protobuf::FileDescriptor* file = v1::Session::descriptor()->file();
  std::vector<const MethodDescriptor*> methods;
  for (int s = 0; s < file->service_count(); ++s) {
    for (int m = 0; m < file->service(s)->method_count(); ++m) {
      methods.push_back(file->service(s)->method(m));
    }
  }
  return methods;
}

std::string PathOf(const MethodDescriptor& method) {
  return "/" + method.service()->full_name() + "/" + method.name();
}

std::string RequestBytes(const MethodDescriptor& method, const std::string& session_id) {
  const google::protobuf::Message* prototype =
      google::protobuf::MessageFactory::generated_factory()->GetPrototype(method.input_type());
  std::unique_ptr<google::protobuf::Message> request(prototype->New());
  if (const auto* field = method.input_type()->FindFieldByName("session_id");
      field != nullptr && !session_id.empty()) {
    request->GetReflection()->SetString(request.get(), field, session_id);
  }
  return request->SerializeAsString();
}

RawReply CallRaw(const std::shared_ptr<grpc::Channel>& channel, const std::string& path,
                 const std::string& request, const std::string& header,
                 std::chrono::milliseconds deadline, int max_messages) {
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + deadline);
  if (!header.empty()) context.AddMetadata("authorization", header);
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
      stub.PrepareCall(&context, path, &cq);
  // One operation at a time, so the next event is always the one just started.
  auto await = [&cq]() {
    void* tag = nullptr;
    bool ok = false;
    return cq.Next(&tag, &ok) && ok;
  };
  RawReply reply;
  call->StartCall(nullptr);
  bool alive = await();
  if (alive) {
    grpc::Slice slice(request);
    grpc::ByteBuffer buffer(&slice, 1);
    call->Write(buffer, nullptr);
    alive = await();
  }
  if (alive) {
    call->WritesDone(nullptr);
    alive = await();
  }
  for (;;) {
    grpc::ByteBuffer in;
    call->Read(&in, nullptr);
    if (!await()) break;
    if (++reply.messages >= max_messages) context.TryCancel();
  }
  call->Finish(&reply.status, nullptr);
  await();
  cq.Shutdown();
  void* tag = nullptr;
  bool ok = false;
  while (cq.Next(&tag, &ok)) {
  }
  return reply;
}

std::string AbsentDevicesToml(const std::string& database, int dead_port,
                              const std::string& log_level) {
  std::ostringstream t;
  t << "[server]\nlisten = \"127.0.0.1:0\"\n"
    << "[storage]\ndatabase = \"" << database << "\"\n"
    << "[meter]\nport = \"/dev/brdfd-test-no-such-port\"\n"
    << "[stage]\naddress = \"127.0.0.1:" << dead_port << "\"\nresponse_timeout_ms = 100\n"
    << "[[auth.tokens]]\nname = \"" << kOperatorName << "\"\ntoken = \"" << kOperatorToken
    << "\"\nrole = \"operator\"\n"
    << "[[auth.tokens]]\nname = \"test-analyst\"\ntoken = \"" << kAnalystToken
    << "\"\nrole = \"analyst\"\n"
    << "[log]\nlevel = \"" << log_level << "\"\n";
  return t.str();
}

}  // namespace brdf::testing
