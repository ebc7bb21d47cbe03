#include "daemon/api/common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "core/geometry.h"
#include "daemon/engine/session_manager.h"
#include "daemon/engine/steps.h"

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
  switch (quantity) {
    case v1::QUANTITY_UNSPECIFIED:
    case v1::QUANTITY_BRDF:
      *out = Quantity::kBrdf;
      return grpc::Status::OK;
    case v1::QUANTITY_RADIANCE:
      *out = Quantity::kRadiance;
      return grpc::Status::OK;
    case v1::QUANTITY_REFLECTANCE:
      *out = Quantity::kReflectance;
      return grpc::Status::OK;
    default:
      return InvalidField("quantity", "unknown quantity " + std::to_string(quantity) +
                                          "; use RADIANCE, REFLECTANCE or BRDF");
  }
}

grpc::Status ParseMethodField(int method, interp::Method* out) {
  switch (method) {
    case v1::INTERPOLATION_METHOD_UNSPECIFIED:
    case v1::INTERPOLATION_METHOD_OCTANT:
      *out = interp::Method::kOctant;
      return grpc::Status::OK;
    case v1::INTERPOLATION_METHOD_DELAUNAY:
      *out = interp::Method::kDelaunay;
      return grpc::Status::OK;
    case v1::INTERPOLATION_METHOD_NEAREST:
      *out = interp::Method::kNearest;
      return grpc::Status::OK;
    default:
      return InvalidField("method", "unknown interpolation method " + std::to_string(method) +
                                        "; use OCTANT, DELAUNAY or NEAREST");
  }
}

grpc::Status ParseCoordinatesField(int coordinates, interp::Coordinates* out) {
  switch (coordinates) {
    case v1::INTERPOLATION_COORDINATES_UNSPECIFIED:
    case v1::INTERPOLATION_COORDINATES_INCIDENCE:
      *out = interp::Coordinates::kIncidence;
      return grpc::Status::OK;
    case v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE:
      *out = interp::Coordinates::kHalfDifference;
      return grpc::Status::OK;
    default:
      return InvalidField("options.coordinates", "unknown coordinates " +
                                                     std::to_string(coordinates) +
                                                     "; use INCIDENCE or HALF_DIFFERENCE");
  }
}

grpc::Status ParseTrendField(int trend, interp::Trend* out) {
  switch (trend) {
    case v1::INTERPOLATION_TREND_UNSPECIFIED:
    case v1::INTERPOLATION_TREND_NONE:
      *out = interp::Trend::kNone;
      return grpc::Status::OK;
    case v1::INTERPOLATION_TREND_BIVARIATE:
      *out = interp::Trend::kBivariate;
      return grpc::Status::OK;
    default:
      return InvalidField("options.trend",
                          "unknown trend " + std::to_string(trend) + "; use NONE or BIVARIATE");
  }
}

v1::Quantity ToProtoQuantity(Quantity quantity) {
  switch (quantity) {
    case Quantity::kRadiance:
      return v1::QUANTITY_RADIANCE;
    case Quantity::kReflectance:
      return v1::QUANTITY_REFLECTANCE;
    case Quantity::kBrdf:
      break;
  }
  return v1::QUANTITY_BRDF;
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
    v1::SessionStateEvent* out = response->add_events();
    out->set_id(e.id);
    out->set_state(ToProtoState(e.state));
    out->set_reason(e.reason);
    *out->mutable_at() = ToTimestamp(e.at);
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

v1::WavelengthGrid ToProtoGrid(const WavelengthGrid& grid) {
  v1::WavelengthGrid g;
  g.set_start_nm(grid.start_nm);
  g.set_step_nm(grid.step_nm);
  g.set_count(static_cast<std::uint32_t>(grid.count));
  return g;
}

v1::ReadingKind ToProtoReadingKind(storage::ReadingKind kind) {
  switch (kind) {
    case storage::ReadingKind::kSample:
      return v1::READING_KIND_SAMPLE;
    case storage::ReadingKind::kReference:
      return v1::READING_KIND_REFERENCE;
    case storage::ReadingKind::kDark:
      return v1::READING_KIND_DARK;
  }
  return v1::READING_KIND_UNSPECIFIED;
}

v1::Reading ToProtoReading(const storage::ReadingRecord& r, const ReadingExtras& extras) {
  v1::Reading out;
  out.set_id(r.id);
  out.set_session_id(std::to_string(r.session_id));
  out.set_step_index(r.step_index);
  out.set_kind(ToProtoReadingKind(r.kind));
  *out.mutable_pose() = ToProtoPose(r.pose);
  *out.mutable_directions() = ToProtoDirections(r.directions);
  const IsoDirection iso = ToIsotropic(r.directions);
  out.mutable_iso()->set_theta_i(iso.theta_i);
  out.mutable_iso()->set_theta_o(iso.theta_o);
  out.mutable_iso()->set_phi(iso.phi);
  *out.mutable_grid() = ToProtoGrid(r.grid);
  out.mutable_radiance()->Add(r.spectrum.begin(), r.spectrum.end());
  out.set_quality_code(r.quality_code);
  out.set_flagged(r.flagged);
  if (r.flagged) out.set_flag_reason(r.note.empty() ? "flagged by the quality policy" : r.note);
  out.set_integration_ms(static_cast<std::uint32_t>(std::max(0, r.integration_ms)));
  out.set_averages(extras.averages);
  out.set_reference_id(r.reference_reading_id.value_or(0));
  out.set_dark_id(r.dark_reading_id.value_or(0));
  out.set_attempts(static_cast<std::uint32_t>(std::max(1, r.attempts)));
  *out.mutable_taken_at() = ToTimestamp(r.recorded_at);
  auto label = extras.step_labels.find(r.step_index);
  if (label != extras.step_labels.end()) out.set_label(label->second);
  return out;
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
  *out = static_cast<double>(t.seconds()) + t.nanos() * 1e-9;
  return grpc::Status::OK;
}

}  // namespace

grpc::Status ParseReadingKinds(const v1::StreamReadingsRequest& request,
                               std::set<storage::ReadingKind>* kinds) {
  for (int i = 0; i < request.kinds_size(); ++i) {
    switch (request.kinds(i)) {
      case v1::READING_KIND_SAMPLE:
        kinds->insert(storage::ReadingKind::kSample);
        break;
      case v1::READING_KIND_REFERENCE:
        kinds->insert(storage::ReadingKind::kReference);
        break;
      case v1::READING_KIND_DARK:
        kinds->insert(storage::ReadingKind::kDark);
        break;
      default:
        return InvalidField("kinds[" + std::to_string(i) + "]",
                            "unknown reading kind " + std::to_string(request.kinds(i)) +
                                "; use READING_KIND_SAMPLE, _REFERENCE or _DARK");
    }
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
  const double created =
      static_cast<double>(session.created_at().seconds()) + session.created_at().nanos() * 1e-9;
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
