// gRPC server reflection, grpc.reflection.v1 and grpc.reflection.v1alpha (the same protocol under
// two package names; current clients such as grpcurl ask for v1 first), answered from the
// descriptors compiled into brdfd (protobuf's generated pool): list_services, file_by_filename,
// file_containing_symbol, file_containing_extension, all_extension_numbers_of_type. A file comes
// with the files it imports that the stream has not sent yet. No token is needed (token_gate.h);
// each stream counts against [server] max_streams_unauthenticated (stream_registry.h), and
// errors quote at most a short printable prefix of what the client asked for.
//
// brdfd serves reflection itself rather than through gRPC's reflection plugin, which only knows
// v1alpha in Debian's gRPC 1.51 and whose streams could not be capped.
#pragma once

#include <string>
#include <vector>

#include "daemon/rpc/stream_registry.h"
#include "grpc/reflection/v1/reflection.grpc.pb.h"
#include "grpc/reflection/v1alpha/reflection.grpc.pb.h"

namespace brdf::daemon {

// The answer to one request, for either version's messages.
template <class Request, class Response>
void AnswerReflection(const std::vector<std::string>& services, const Request& request,
                      std::vector<std::string>* sent_files, Response* response);

// One version's service: `Base` is grpc::reflection::v1[alpha]::ServerReflection::Service.
template <class Base, class Request, class Response>
class ReflectionServiceOf final : public Base {
 public:
  // `services`: the fully qualified names list_services answers. `streams` must outlive it.
  ReflectionServiceOf(std::vector<std::string> services, StreamRegistry& streams)
      : services_(std::move(services)), streams_(streams) {}

  grpc::Status ServerReflectionInfo(grpc::ServerContext* context,
                                    grpc::ServerReaderWriter<Response, Request>* stream) override {
    std::unique_ptr<StreamRegistry::Slot> slot;
    if (grpc::Status st = streams_.Open(*context, nullptr, "reflection", &slot); !st.ok()) {
      return st;
    }
    std::vector<std::string> sent_files;
    Request request;
    while (stream->Read(&request)) {
      Response response;
      AnswerReflection(services_, request, &sent_files, &response);
      if (!slot->Write(stream, response)) break;
    }
    return grpc::Status::OK;
  }

 private:
  const std::vector<std::string> services_;
  StreamRegistry& streams_;
};

using ReflectionV1Service = ReflectionServiceOf<grpc::reflection::v1::ServerReflection::Service,
                                                grpc::reflection::v1::ServerReflectionRequest,
                                                grpc::reflection::v1::ServerReflectionResponse>;
using ReflectionV1AlphaService =
    ReflectionServiceOf<grpc::reflection::v1alpha::ServerReflection::Service,
                        grpc::reflection::v1alpha::ServerReflectionRequest,
                        grpc::reflection::v1alpha::ServerReflectionResponse>;

}  // namespace brdf::daemon
