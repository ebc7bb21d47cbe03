#include "daemon/api/common.h"

#include <cmath>
#include <optional>
#include <sstream>

#include "daemon/sessions/session_id.h"
#include "daemon/wire/enums.h"

namespace brdf::daemon {

grpc::Status ToGrpcStatus(const Status& status) {
  using grpc::StatusCode;
  StatusCode code = StatusCode::INTERNAL;
  switch (status.code()) {
    case brdf::StatusCode::kOk:
      return grpc::Status::OK;
    case brdf::StatusCode::kInvalidArgument:
      code = StatusCode::INVALID_ARGUMENT;
      break;
    case brdf::StatusCode::kNotFound:
      code = StatusCode::NOT_FOUND;
      break;
    case brdf::StatusCode::kFailedPrecondition:
      code = StatusCode::FAILED_PRECONDITION;
      break;
    case brdf::StatusCode::kTimeout:
      code = StatusCode::DEADLINE_EXCEEDED;
      break;
    case brdf::StatusCode::kCancelled:
      code = StatusCode::CANCELLED;
      break;
    case brdf::StatusCode::kDeviceError:
    case brdf::StatusCode::kProtocolError:
    case brdf::StatusCode::kDisconnected:
    case brdf::StatusCode::kIoError:
      code = StatusCode::UNAVAILABLE;
      break;
    case brdf::StatusCode::kConfigurationError:
    case brdf::StatusCode::kInternal:
      code = StatusCode::INTERNAL;
      break;
  }
  return grpc::Status(code, BoundedMessage(status.message()));
}

std::string BoundedMessage(std::string message) {
  if (message.size() <= kMaxErrorMessageBytes) return message;
  std::size_t cut = kMaxErrorMessageBytes - 32;
  // Not inside a UTF-8 sequence: back up over continuation bytes (10xxxxxx).
  while (cut > 0 && (static_cast<unsigned char>(message[cut]) & 0xC0) == 0x80) --cut;
  const std::size_t full = message.size();
  message.resize(cut);
  return message + "... (" + std::to_string(full) + " bytes)";
}

grpc::Status InvalidField(const std::string& field, const std::string& what) {
  return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, BoundedMessage(field + ": " + what));
}

grpc::Status ParseQuantityField(int quantity, Quantity* out) {
  const std::optional<Quantity> q = FromProtoQuantity(quantity);
  if (!q.has_value()) {
    return InvalidField("quantity", "unknown quantity " + std::to_string(quantity) +
                                        "; use RADIANCE, REFLECTANCE or BRDF");
  }
  *out = *q;
  return grpc::Status::OK;
}

grpc::Status ParseMethodField(int method, interp::Method* out) {
  const std::optional<interp::Method> m = FromProtoMethod(method);
  if (!m.has_value()) {
    return InvalidField("method", "unknown interpolation method " + std::to_string(method) +
                                      "; use OCTANT, DELAUNAY or NEAREST");
  }
  *out = *m;
  return grpc::Status::OK;
}

grpc::Status ParseCoordinatesField(int coordinates, interp::Coordinates* out) {
  const std::optional<interp::Coordinates> c = FromProtoCoordinates(coordinates);
  if (!c.has_value()) {
    return InvalidField("options.coordinates", "unknown coordinates " +
                                                   std::to_string(coordinates) +
                                                   "; use INCIDENCE or HALF_DIFFERENCE");
  }
  *out = *c;
  return grpc::Status::OK;
}

grpc::Status ParseTrendField(int trend, interp::Trend* out) {
  const std::optional<interp::Trend> t = FromProtoTrend(trend);
  if (!t.has_value()) {
    return InvalidField("options.trend",
                        "unknown trend " + std::to_string(trend) + "; use NONE or BIVARIATE");
  }
  *out = *t;
  return grpc::Status::OK;
}

grpc::Status ParseSessionIdField(const std::string& text, const std::string& field,
                                 std::int64_t* id) {
  if (text.size() > kMaxSessionIdBytes) {
    return InvalidField(field, "is " + std::to_string(text.size()) +
                                   " bytes long; a session id is a positive number of at most 18 "
                                   "digits, as SubmitPlan returned it");
  }
  Result<SessionId> parsed = ParseSessionId(text, field);
  if (!parsed.ok()) return ToGrpcStatus(parsed.status());
  *id = *parsed;
  return grpc::Status::OK;
}

std::string ShortNumber(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

Status CheckAngle(double value, double lo, double hi, const std::string& field) {
  if (!std::isfinite(value)) {
    return InvalidArgument(field + ": must be a finite angle in degrees (got " +
                           ShortNumber(value) + ")");
  }
  if (value < lo || value > hi) {
    return InvalidArgument(field + ": " + ShortNumber(value) + "° is outside [" + ShortNumber(lo) +
                           ", " + ShortNumber(hi) + "] degrees");
  }
  return Status::Ok();
}

void StopSignal::Stop() {
  {
    MutexLock lock(mu_);
    stopped_ = true;
  }
  cv_.NotifyAll();
}

bool StopSignal::WaitFor(std::chrono::steady_clock::duration d) const {
  MutexLock lock(mu_);
  return cv_.WaitFor(mu_, d, [this] { return stopped_.load(); });
}

grpc::Status ParseReadingKinds(const v1::StreamReadingsRequest& request,
                               std::set<storage::ReadingKind>* kinds) {
  for (int i = 0; i < request.kinds_size(); ++i) {
    const std::optional<ReadingKind> kind = FromProtoReadingKind(request.kinds(i));
    if (!kind.has_value()) {
      return InvalidField("kinds[" + std::to_string(i) + "]",
                          "unknown reading kind " + std::to_string(request.kinds(i)) +
                              "; use READING_KIND_SAMPLE, _REFERENCE or _DARK");
    }
    kinds->insert(*kind);
  }
  return grpc::Status::OK;
}

}  // namespace brdf::daemon
