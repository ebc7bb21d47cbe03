// Errors as values. Every fallible call in brdfd returns a Status or a Result<T>; nothing throws
// across a component boundary. A Status carries a code a program can branch on and a message an
// operator can act on: what failed, where, and what to do.
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace brdf {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,     // the caller's input is wrong (a field, a value, a file's content)
  kNotFound,            // a named thing (session, reading, file) does not exist
  kFailedPrecondition,  // the request is valid but not now (wrong state)
  kTimeout,             // a device or peer did not answer within its deadline
  kCancelled,           // the caller cancelled the call (pause immediate, abort, shutdown)
  kDeviceError,         // the device answered with an error code of its own (see device_code)
  kProtocolError,       // the device answered with bytes that do not parse
  kDisconnected,        // the link to the device is down (port gone, socket closed)
  kConfigurationError,  // the configuration cannot work (bad register address, bad port name)
  kIoError,             // the local system failed (disk full, read-only database)
  kInternal,            // a bug: an invariant of ours did not hold
};

// Short lower-case name of a code ("timeout", "device_error", ...), for logs and APIs.
const char* StatusCodeName(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;  // OK
  Status(StatusCode code, std::string message, int device_code = 0)
      : code_(code), message_(std::move(message)), device_code_(device_code) {}

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // For kDeviceError: the device's own code (a PR-650 quality code, a Modbus exception code).
  int device_code() const { return device_code_; }

  // "timeout: PR-650 on /dev/ttyUSB0 did not answer M0 within 30 s; ..."
  std::string ToString() const;

  // Prefixes context to the message: Status(...).WithContext("moving to pose 12").
  Status WithContext(const std::string& context) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
  int device_code_ = 0;
};

// Convenience constructors.
inline Status InvalidArgument(std::string m) {
  return {StatusCode::kInvalidArgument, std::move(m)};
}
inline Status NotFound(std::string m) {
  return {StatusCode::kNotFound, std::move(m)};
}
inline Status FailedPrecondition(std::string m) {
  return {StatusCode::kFailedPrecondition, std::move(m)};
}
inline Status Timeout(std::string m) {
  return {StatusCode::kTimeout, std::move(m)};
}
inline Status Cancelled(std::string m) {
  return {StatusCode::kCancelled, std::move(m)};
}
inline Status DeviceError(int device_code, std::string m) {
  return {StatusCode::kDeviceError, std::move(m), device_code};
}
inline Status ProtocolError(std::string m) {
  return {StatusCode::kProtocolError, std::move(m)};
}
inline Status Disconnected(std::string m) {
  return {StatusCode::kDisconnected, std::move(m)};
}
inline Status ConfigurationError(std::string m) {
  return {StatusCode::kConfigurationError, std::move(m)};
}
inline Status IoError(std::string m) {
  return {StatusCode::kIoError, std::move(m)};
}
inline Status Internal(std::string m) {
  return {StatusCode::kInternal, std::move(m)};
}

// A value or the Status that explains why there is none.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}        // NOLINT: implicit by design
  Result(Status status) : v_(std::move(status)) {  // NOLINT: implicit by design
    assert(!std::get<Status>(v_).ok() && "Result built from an OK status has no value");
  }

  bool ok() const { return std::holds_alternative<T>(v_); }
  const Status& status() const {
    static const Status kOk;
    return ok() ? kOk : std::get<Status>(v_);
  }
  T& value() & { return std::get<T>(v_); }
  const T& value() const& { return std::get<T>(v_); }
  T&& value() && { return std::get<T>(std::move(v_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Status> v_;
};

}  // namespace brdf

// Returns early from the enclosing function when `expr` (a Status) is not OK.
#define BRDF_RETURN_IF_ERROR(expr)               \
  do {                                           \
    ::brdf::Status brdf_status_ = (expr);        \
    if (!brdf_status_.ok()) return brdf_status_; \
  } while (false)

// Unwraps `expr` (a Result<T>) into `lhs` (a declaration such as `auto rows` or an lvalue), or
// returns its Status from the enclosing function:
//   BRDF_ASSIGN_OR_RETURN(const Session session, store.GetSession(id));
// Expands to statements, not an expression: not the sole body of an unbraced if or loop.
#define BRDF_ASSIGN_OR_RETURN(lhs, expr) \
  BRDF_ASSIGN_OR_RETURN_IMPL_(BRDF_STATUS_CONCAT_(brdf_result_, __LINE__), lhs, expr)
#define BRDF_STATUS_CONCAT_INNER_(a, b) a##b
#define BRDF_STATUS_CONCAT_(a, b) BRDF_STATUS_CONCAT_INNER_(a, b)
#define BRDF_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                                \
  if (!tmp.ok()) return tmp.status();               \
  lhs = std::move(tmp).value()
