#include "daemon/api/common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <sstream>

#include "daemon/sessions/session_id.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/session.h"
#include "daemon/wire/values.h"

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

grpc::Status ServeWhoAmI(const Authenticator& auth, const grpc::ServerContextBase& context,
                         const char* server, v1::Caller* response) {
  Caller caller;
  if (grpc::Status st = auth.CallerOf(context, &caller); !st.ok()) return st;
  response->set_name(caller.name);
  response->set_role(RoleName(caller.role));
  response->set_server(server);
  return grpc::Status::OK;
}

grpc::Status ServeListSessionEvents(storage::SessionReader& reader,
                                    const v1::ListSessionEventsRequest& request,
                                    v1::ListSessionEventsResponse* response) {
  std::int64_t id = 0;
  if (grpc::Status st = ParseSessionIdField(request.session_id(), "session_id", &id); !st.ok()) {
    return st;
  }
  Result<std::vector<storage::SessionEventRecord>> events = reader.ListSessionEvents(id);
  if (!events.ok()) return ToGrpcStatus(events.status());
  response->mutable_events()->Reserve(static_cast<int>(events->size()));
  for (const storage::SessionEventRecord& e : *events) {
    *response->add_events() = ToProtoStateEvent(e);
  }
  return grpc::Status::OK;
}

namespace {
std::string Num(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}
}  // namespace

Status CheckAngle(double value, double lo, double hi, const std::string& field) {
  if (!std::isfinite(value)) {
    return InvalidArgument(field + ": must be a finite angle in degrees (got " + Num(value) + ")");
  }
  if (value < lo || value > hi) {
    return InvalidArgument(field + ": " + Num(value) + "° is outside [" + Num(lo) + ", " + Num(hi) +
                           "] degrees");
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

namespace {

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

grpc::Status TimestampField(const v1::ListSessionsRequest& request, bool after,
                            std::optional<double>* out) {
  if (after ? !request.has_created_after() : !request.has_created_before()) return grpc::Status::OK;
  const google::protobuf::Timestamp& t = after ? request.created_after() : request.created_before();
  if (t.nanos() < 0 || t.nanos() > 999999999) {
    return InvalidField(after ? "created_after" : "created_before",
                        "nanos " + std::to_string(t.nanos()) + " is outside 0 … 999,999,999");
  }
  *out = ToUnixSeconds(t);
  return grpc::Status::OK;
}

}  // namespace

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

bool CatalogueFilter::Matches(const v1::Session& session) const {
  if (!rig.empty() && session.rig() != rig) return false;
  const v1::Sample& s = session.sample();
  if (!sample.empty() && s.id() != sample && Lower(s.name()) != Lower(sample)) return false;
  if (!material.empty() && Lower(s.material()) != Lower(material)) return false;
  if (!tag.empty() && std::find(s.tags().begin(), s.tags().end(), tag) == s.tags().end()) {
    return false;
  }
  const double created = ToUnixSeconds(session.created_at());
  if (created_after.has_value() && created < *created_after) return false;
  if (created_before.has_value() && !(created < *created_before)) return false;
  return true;
}

grpc::Status ParseCatalogueFilter(const v1::ListSessionsRequest& request, CatalogueFilter* out) {
  CatalogueFilter f;
  for (int i = 0; i < request.states_size(); ++i) {
    const int state = request.states(i);
    if (!v1::SessionState_IsValid(state) || state == v1::SESSION_STATE_UNSPECIFIED) {
      return InvalidField("states[" + std::to_string(i) + "]",
                          "unknown session state " + std::to_string(state));
    }
    f.states.push_back(FromProtoState(static_cast<v1::SessionState>(state)));
  }
  f.rig = request.rig();
  f.sample = request.sample();
  f.material = request.material();
  f.tag = request.tag();
  if (grpc::Status st = TimestampField(request, true, &f.created_after); !st.ok()) return st;
  if (grpc::Status st = TimestampField(request, false, &f.created_before); !st.ok()) return st;
  if (f.created_after && f.created_before && !(*f.created_after < *f.created_before)) {
    return InvalidField("created_before", "must be later than created_after");
  }
  *out = std::move(f);
  return grpc::Status::OK;
}

}  // namespace brdf::daemon
