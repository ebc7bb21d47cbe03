#include "tools/brdfctl/rpc_error.h"

#include "tools/brdfctl/exit_codes.h"

namespace brdf::ctl {

const char* GrpcCodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return "OK";
    case grpc::StatusCode::CANCELLED:
      return "CANCELLED";
    case grpc::StatusCode::UNKNOWN:
      return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND:
      return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS:
      return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED:
      return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION:
      return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED:
      return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE:
      return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED:
      return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL:
      return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE:
      return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS:
      return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED:
      return "UNAUTHENTICATED";
    default:
      return "UNKNOWN_CODE";
  }
}

int ExitCodeFor(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return kExitOk;
    case grpc::StatusCode::INVALID_ARGUMENT:
      return kExitInvalid;
    case grpc::StatusCode::UNAUTHENTICATED:
    case grpc::StatusCode::PERMISSION_DENIED:
      return kExitAuth;
    default:
      return kExitFailure;
  }
}

std::string DescribeRpcError(const grpc::Status& status, std::string_view call,
                             std::string_view address) {
  std::string out = "brdfctl: " + std::string(call) + ": " + GrpcCodeName(status.error_code()) +
                    ": " + status.error_message();
  switch (status.error_code()) {
    case grpc::StatusCode::UNAVAILABLE:
      out += "\n  hint: is brdfd running and listening on " + std::string(address) +
             "? Set --address or BRDF_ADDRESS (and --tls if the daemon uses TLS).";
      break;
    case grpc::StatusCode::UNAUTHENTICATED:
      out +=
          "\n  hint: give a token the daemon knows ([[auth.tokens]] in its config) with --token "
          "or BRDF_TOKEN.";
      break;
    case grpc::StatusCode::PERMISSION_DENIED:
      out += "\n  hint: this call needs an operator token; analyst tokens may only read.";
      break;
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      out += "\n  hint: the daemon did not answer in time; raise --timeout or check its log.";
      break;
    default:
      break;
  }
  return out;
}

int ReportRpcError(std::ostream& err, const grpc::Status& status, std::string_view call,
                   std::string_view address) {
  err << DescribeRpcError(status, call, address) << "\n";
  return ExitCodeFor(status.error_code());
}

int ReportLocalError(std::ostream& err, const Status& status) {
  err << "brdfctl: " << status.message() << "\n";
  return status.code() == StatusCode::kInvalidArgument || status.code() == StatusCode::kNotFound
             ? kExitInvalid
             : kExitFailure;
}

}  // namespace brdf::ctl
