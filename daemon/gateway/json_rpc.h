// The JSON side of brdfd's own gRPC API, for the web gateway (web_gateway.h): a brdf.v1 method
// named "brdf.v1.<Service>/<Method>" is called on a channel to brdfd's OWN gRPC server (in
// process), its request parsed from JSON and its answers printed as JSON, with protobuf's JSON
// mapping (field names as in brdf.proto, enums by name, 64-bit integers and bytes as strings,
// every field printed, defaults too). A call inside the process does not pass the token gate
// (rpc/token_gate.h), so the gateway is the door of the browser's calls: it admits each call
// with the same table and check (Authenticator::Admit) before making it, and the bearer token
// travels as the "authorization" metadata for the handlers that ask who calls. Validation and
// limits are the gRPC server's, call for call: the gateway adds no rule of its own.
#pragma once

#include <google/protobuf/descriptor.h>
#include <grpcpp/channel.h>
#include <grpcpp/client_context.h>
#include <grpcpp/support/status.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/rpc/auth.h"

namespace brdf::daemon {

// A callable brdf.v1 method: unary or server streaming (the API has no client streams).
struct WebMethod {
  const google::protobuf::MethodDescriptor* descriptor = nullptr;
  std::string path;  // "/brdf.v1.Control/GetSession", as gRPC names it on the wire
  bool server_streaming = false;
};

// The method "brdf.v1.<Service>/<Method>" of brdf.v1's services; nullptr for anything else (an
// unknown name, another package, a client-streaming method). The result lives forever.
const WebMethod* FindWebMethod(std::string_view name);

// "invalid JSON for brdf.v1.GetSessionRequest: <protobuf's reason>" as INVALID_ARGUMENT, or OK
// with *message filled. Unknown fields are refused (a typo must not pass as a default).
grpc::Status ParseJsonRequest(std::string_view json, google::protobuf::Message* message);

// The message as JSON (one line).
std::string ToJson(const google::protobuf::Message& message);

// Top-level fields of the answers to leave out ("radiance"), named as in brdf.proto; the web
// explorer lists 50,000 readings without their spectra this way. A name the answer type does not
// have is INVALID_ARGUMENT (naming the known fields).
using OmitFields = std::vector<const google::protobuf::FieldDescriptor*>;
grpc::Status ParseOmit(const WebMethod& method, std::string_view comma_separated,
                       OmitFields* fields);

// The gRPC status as the gateway's JSON error body: {"code":"PERMISSION_DENIED","message":"…"}.
std::string StatusJson(const grpc::Status& status);

// The HTTP status the gateway answers a gRPC status with (401, 403, 400, 404, 409, 413/429, 503,
// 504, 500; 200 for OK).
int HttpStatusFor(grpc::StatusCode code);

class JsonRpc {
 public:
  // `channel` leads to the program's own gRPC server (in process); `auth` is that server's and
  // must outlive this.
  JsonRpc(std::shared_ptr<grpc::Channel> channel, const Authenticator& auth)
      : channel_(std::move(channel)), auth_(auth) {}

  // Calls a unary method with the JSON request; *json_out gets the response (OK) or is left
  // alone. `authorization` empty: no metadata (the server then says UNAUTHENTICATED when tokens
  // are configured).
  grpc::Status Unary(const WebMethod& method, std::string_view json_request,
                     const std::string& authorization, std::chrono::milliseconds deadline,
                     std::string* json_out) const;

  // Calls a server-streaming method; each answer goes to on_message as JSON; on_message returns
  // false to cancel the call. `context` is the caller's so that another thread may TryCancel it;
  // fresh, one per call.
  grpc::Status Stream(const WebMethod& method, std::string_view json_request,
                      const std::string& authorization, const OmitFields& omit,
                      grpc::ClientContext* context,
                      const std::function<bool(std::string json)>& on_message) const;

 private:
  std::shared_ptr<grpc::Channel> channel_;
  const Authenticator& auth_;
};

}  // namespace brdf::daemon
