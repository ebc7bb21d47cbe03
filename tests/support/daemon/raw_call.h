// Calling any of brdfd's RPCs without its generated stub: the methods of brdf.proto from its
// descriptor, requests as bytes (so that a test can send what no stub would: unknown fields,
// deep nesting, garbage), one generic call that serves unary and server-streaming methods alike.
// Used by the auth matrix and the input-limits tests, which must cover EVERY RPC.
#pragma once

#include <google/protobuf/descriptor.h>
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

namespace brdf::testing {

// Every method of every service of brdf.proto.
std::vector<const google::protobuf::MethodDescriptor*> AllMethods();

// "/brdf.v1.Control/SubmitPlan"
std::string PathOf(const google::protobuf::MethodDescriptor& method);

// The method's request message serialized: empty, or with `session_id` set where the request
// has such a field.
std::string RequestBytes(const google::protobuf::MethodDescriptor& method,
                         const std::string& session_id = "");

struct RawReply {
  grpc::Status status;
  int messages = 0;  // replies received
};

// One call of `path` with `request` as its only message and "authorization: <header>" (none
// when empty). Reads up to `max_messages` replies, then cancels (for streams that would go on).
RawReply CallRaw(const std::shared_ptr<grpc::Channel>& channel, const std::string& path,
                 const std::string& request, const std::string& header,
                 std::chrono::milliseconds deadline = std::chrono::seconds(15),
                 int max_messages = 1000);

// A brdfd configuration without devices (no such serial port, nothing on `dead_port`), listening
// on 127.0.0.1:0, with the operator and analyst tokens of daemon/test_rig.h.
std::string AbsentDevicesToml(const std::string& database, int dead_port,
                              const std::string& log_level = "info");

}  // namespace brdf::testing
