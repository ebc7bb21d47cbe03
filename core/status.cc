#include "core/status.h"

namespace brdf {

const char* StatusCodeName(StatusCode code) {
  switch (code) {
    case StatusCode::kOk:
      return "ok";
    case StatusCode::kInvalidArgument:
      return "invalid_argument";
    case StatusCode::kNotFound:
      return "not_found";
    case StatusCode::kFailedPrecondition:
      return "failed_precondition";
    case StatusCode::kTimeout:
      return "timeout";
    case StatusCode::kCancelled:
      return "cancelled";
    case StatusCode::kDeviceError:
      return "device_error";
    case StatusCode::kProtocolError:
      return "protocol_error";
    case StatusCode::kDisconnected:
      return "disconnected";
    case StatusCode::kConfigurationError:
      return "configuration_error";
    case StatusCode::kIoError:
      return "io_error";
    case StatusCode::kInternal:
      return "internal";
  }
  return "unknown";
}

std::string Status::ToString() const {
  if (ok()) return "ok";
  std::string s = StatusCodeName(code_);
  if (code_ == StatusCode::kDeviceError) s += " " + std::to_string(device_code_);
  return s + ": " + message_;
}

Status Status::WithContext(const std::string& context) const {
  if (ok()) return *this;
  return Status(code_, context + ": " + message_, device_code_);
}

}  // namespace brdf
