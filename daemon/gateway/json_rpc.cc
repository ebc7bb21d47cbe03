#include "daemon/gateway/json_rpc.h"

#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/message.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/impl/client_unary_call.h>
#include <grpcpp/impl/rpc_method.h>
#include <grpcpp/support/sync_stream.h>

#include <map>

#include "brdf/v1/brdf.grpc.pb.h"
#include "core/client_text.h"
#include "core/json_text.h"

namespace brdf::daemon {
namespace {

namespace pb = google::protobuf;

// Every unary and server-streaming method of brdf.v1's services, by "brdf.v1.Service/Method".
std::map<std::string, WebMethod, std::less<>> BuildMethods() {
  // Naming a generated type links brdf.proto into the generated pool.
  const pb::FileDescriptor* file = brdf::v1::Session::descriptor()->file();
  std::map<std::string, WebMethod, std::less<>> methods;
  for (int s = 0; s < file->service_count(); ++s) {
    const pb::ServiceDescriptor* service = file->service(s);
    for (int m = 0; m < service->method_count(); ++m) {
      const pb::MethodDescriptor* method = service->method(m);
      if (method->client_streaming()) continue;
      WebMethod entry;
      entry.descriptor = method;
      entry.path = "/" + service->full_name() + "/" + method->name();
      entry.server_streaming = method->server_streaming();
      methods.emplace(service->full_name() + "/" + method->name(), std::move(entry));
    }
  }
  return methods;
}

std::unique_ptr<pb::Message> NewMessage(const pb::Descriptor* type) {
  return std::unique_ptr<pb::Message>(
      pb::MessageFactory::generated_factory()->GetPrototype(type)->New());
}

const char* CodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::OK:
      return "OK";
    case grpc::CANCELLED:
      return "CANCELLED";
    case grpc::UNKNOWN:
      return "UNKNOWN";
    case grpc::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case grpc::DEADLINE_EXCEEDED:
      return "DEADLINE_EXCEEDED";
    case grpc::NOT_FOUND:
      return "NOT_FOUND";
    case grpc::ALREADY_EXISTS:
      return "ALREADY_EXISTS";
    case grpc::PERMISSION_DENIED:
      return "PERMISSION_DENIED";
    case grpc::UNAUTHENTICATED:
      return "UNAUTHENTICATED";
    case grpc::RESOURCE_EXHAUSTED:
      return "RESOURCE_EXHAUSTED";
    case grpc::FAILED_PRECONDITION:
      return "FAILED_PRECONDITION";
    case grpc::ABORTED:
      return "ABORTED";
    case grpc::OUT_OF_RANGE:
      return "OUT_OF_RANGE";
    case grpc::UNIMPLEMENTED:
      return "UNIMPLEMENTED";
    case grpc::INTERNAL:
      return "INTERNAL";
    case grpc::UNAVAILABLE:
      return "UNAVAILABLE";
    case grpc::DATA_LOSS:
      return "DATA_LOSS";
    default:
      return "UNKNOWN";
  }
}

// The request parsed, then admitted as the token gate admits a call from the network (the same
// table and check: Authenticator::Admit); the token goes along for the handler's CallerOf.
grpc::Status PrepareRequest(const WebMethod& method, std::string_view json,
                            const std::string& authorization, const Authenticator& auth,
                            grpc::ClientContext* context, std::unique_ptr<pb::Message>* request) {
  *request = NewMessage(method.descriptor->input_type());
  if (grpc::Status st = ParseJsonRequest(json, request->get()); !st.ok()) return st;
  Caller caller;
  if (grpc::Status st = auth.Admit(method.path, authorization, "the web gateway", &caller);
      !st.ok()) {
    return st;
  }
  if (!authorization.empty()) context->AddMetadata("authorization", authorization);
  return grpc::Status::OK;
}

}  // namespace

const WebMethod* FindWebMethod(std::string_view name) {
  static const std::map<std::string, WebMethod, std::less<>> methods = BuildMethods();
  auto it = methods.find(name);
  return it == methods.end() ? nullptr : &it->second;
}

grpc::Status ParseJsonRequest(std::string_view json, pb::Message* message) {
  pb::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  // An empty body is the empty message ({}), as for GetRigStatus.
  const std::string text = json.find_first_not_of(" \t\r\n") == std::string_view::npos
                               ? std::string("{}")
                               : std::string(json);
  const auto st = pb::util::JsonStringToMessage(text, message, options);
  if (!st.ok()) {
    return grpc::Status(grpc::INVALID_ARGUMENT,
                        "invalid JSON for " + message->GetDescriptor()->full_name() + ": " +
                            PrintablePrefix(std::string(st.message()), 200) +
                            "; send the request message as protobuf JSON (brdf.proto's field "
                            "names, enums by name)");
  }
  return grpc::Status::OK;
}

std::string ToJson(const pb::Message& message) {
  pb::util::JsonPrintOptions options;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string out;
  (void)pb::util::MessageToJsonString(message, &out, options);  // generated types always print
  return out;
}

std::string StatusJson(const grpc::Status& status) {
  return std::string("{\"code\":\"") + CodeName(status.error_code()) +
         "\",\"message\":" + JsonString(status.error_message()) + "}";
}

int HttpStatusFor(grpc::StatusCode code) {
  switch (code) {
    case grpc::OK:
      return 200;
    case grpc::INVALID_ARGUMENT:
    case grpc::OUT_OF_RANGE:
      return 400;
    case grpc::UNAUTHENTICATED:
      return 401;
    case grpc::PERMISSION_DENIED:
      return 403;
    case grpc::NOT_FOUND:
      return 404;
    case grpc::ALREADY_EXISTS:
    case grpc::FAILED_PRECONDITION:
    case grpc::ABORTED:
      return 409;
    case grpc::RESOURCE_EXHAUSTED:
      return 429;
    case grpc::CANCELLED:
      return 499;
    case grpc::UNIMPLEMENTED:
      return 501;
    case grpc::UNAVAILABLE:
      return 503;
    case grpc::DEADLINE_EXCEEDED:
      return 504;
    default:
      return 500;
  }
}

grpc::Status JsonRpc::Unary(const WebMethod& method, std::string_view json_request,
                            const std::string& authorization, std::chrono::milliseconds deadline,
                            std::string* json_out) const {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + deadline);
  std::unique_ptr<pb::Message> request;
  if (grpc::Status st =
          PrepareRequest(method, json_request, authorization, auth_, &context, &request);
      !st.ok()) {
    return st;
  }
  std::unique_ptr<pb::Message> response = NewMessage(method.descriptor->output_type());
  const grpc::internal::RpcMethod rpc(method.path.c_str(), grpc::internal::RpcMethod::NORMAL_RPC);
  grpc::Status st =
      grpc::internal::BlockingUnaryCall<pb::Message, pb::Message, pb::MessageLite, pb::MessageLite>(
          channel_.get(), rpc, &context, *request, response.get());
  if (st.ok()) *json_out = ToJson(*response);
  return st;
}

grpc::Status ParseOmit(const WebMethod& method, std::string_view comma_separated,
                       OmitFields* fields) {
  const pb::Descriptor* type = method.descriptor->output_type();
  std::size_t start = 0;
  while (start < comma_separated.size()) {
    std::size_t end = comma_separated.find(',', start);
    if (end == std::string_view::npos) end = comma_separated.size();
    const std::string name(comma_separated.substr(start, end - start));
    const pb::FieldDescriptor* field = type->FindFieldByName(name);
    if (field == nullptr) {
      std::string known;
      for (int i = 0; i < type->field_count(); ++i) {
        known += (known.empty() ? "" : ", ") + type->field(i)->name();
      }
      return grpc::Status(
          grpc::INVALID_ARGUMENT,
          "omit: " + type->full_name() + " has no field \"" + name + "\" (fields: " + known + ")");
    }
    fields->push_back(field);
    start = end + 1;
  }
  return grpc::Status::OK;
}

grpc::Status JsonRpc::Stream(const WebMethod& method, std::string_view json_request,
                             const std::string& authorization, const OmitFields& omit,
                             grpc::ClientContext* context,
                             const std::function<bool(std::string json)>& on_message) const {
  std::unique_ptr<pb::Message> request;
  if (grpc::Status st =
          PrepareRequest(method, json_request, authorization, auth_, context, &request);
      !st.ok()) {
    return st;
  }
  const grpc::internal::RpcMethod rpc(method.path.c_str(),
                                      grpc::internal::RpcMethod::SERVER_STREAMING);
  std::unique_ptr<grpc::ClientReader<pb::Message>> reader(
      grpc::internal::ClientReaderFactory<pb::Message>::Create(channel_.get(), rpc, context,
                                                               *request));
  std::unique_ptr<pb::Message> answer = NewMessage(method.descriptor->output_type());
  while (reader->Read(answer.get())) {
    for (const pb::FieldDescriptor* field : omit)
      answer->GetReflection()->ClearField(answer.get(), field);
    if (!on_message(ToJson(*answer))) {
      context->TryCancel();
      break;
    }
    answer->Clear();
  }
  return reader->Finish();
}

}  // namespace brdf::daemon
