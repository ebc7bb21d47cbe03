// Turns a failed gRPC call into what the user sees: the status code and the daemon's message,
// a hint about what to do where one is obvious (start the daemon, check the token), and the exit
// status of exit_codes.h.
#pragma once

#include <grpcpp/grpcpp.h>

#include <ostream>
#include <string>
#include <string_view>

#include "core/status.h"

namespace brdf::ctl {

// "INVALID_ARGUMENT", "UNAUTHENTICATED", … (the canonical gRPC names).
const char* GrpcCodeName(grpc::StatusCode code);

// 2 for INVALID_ARGUMENT, 3 for UNAUTHENTICATED and PERMISSION_DENIED, else 1.
int ExitCodeFor(grpc::StatusCode code);

// "brdfctl: SubmitPlan: INVALID_ARGUMENT: <message>" plus a hint line when there is one.
// `call` names the RPC, `address` the daemon (for "cannot reach" hints).
std::string DescribeRpcError(const grpc::Status& status, std::string_view call,
                             std::string_view address);

// Prints DescribeRpcError to `err` and returns ExitCodeFor(status.error_code()).
int ReportRpcError(std::ostream& err, const grpc::Status& status, std::string_view call,
                   std::string_view address);

// A local error (a plan file that does not parse, an unreadable certificate): prints
// "brdfctl: <message>" and returns 2 for kInvalidArgument / kNotFound (the user's input), else 1.
int ReportLocalError(std::ostream& err, const Status& status);

}  // namespace brdf::ctl
