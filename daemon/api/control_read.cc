// The Control service's reads, from the server's SessionCatalogue (control.h).
#include <algorithm>
#include <string>
#include <utility>

#include "daemon/api/control.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/session.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {
namespace {

grpc::Status TimestampField(const v1::ListSessionsRequest& request, bool after,
                            std::optional<double>* out) {
  if (after ? !request.has_created_after() : !request.has_created_before()) return grpc::Status::OK;
  const google::protobuf::Timestamp& t = after ? request.created_after() : request.created_before();
  const std::string field = after ? "created_after" : "created_before";
  // google.protobuf.Timestamp's range: 0001-01-01T00:00:00Z … 9999-12-31T23:59:59Z.
  constexpr std::int64_t kMinSeconds = -62135596800, kMaxSeconds = 253402300799;
  if (t.seconds() < kMinSeconds || t.seconds() > kMaxSeconds) {
    return InvalidField(field + ".seconds",
                        std::to_string(t.seconds()) + " is outside " + std::to_string(kMinSeconds) +
                            " … " + std::to_string(kMaxSeconds) +
                            " (0001-01-01 … 9999-12-31, google.protobuf.Timestamp's range)");
  }
  if (t.nanos() < 0 || t.nanos() > 999999999) {
    return InvalidField(field + ".nanos", std::to_string(t.nanos()) +
                                              " is outside 0 … 999999999 (the fraction of "
                                              "a second, google.protobuf.Timestamp's range)");
  }
  *out = ToUnixSeconds(t);
  return grpc::Status::OK;
}

// ListSessionsRequest's catalogue filters: INVALID_ARGUMENT naming the field for an unknown
// state, a timestamp out of range (seconds outside 0001-01-01 … 9999-12-31, nanos outside
// 0 … 999,999,999) or created_before not after
// created_after.
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

}  // namespace

grpc::Status ControlService::GetSession(grpc::ServerContext* /*context*/,
                                        const v1::GetSessionRequest* request,
                                        v1::Session* response) {
  SessionId id = 0;
  if (grpc::Status st = ParseSessionIdField(request->session_id(), "session_id", &id); !st.ok()) {
    return st;
  }
  Result<v1::Session> session = catalogue_.GetSession(id);
  if (!session.ok()) return ToGrpcStatus(session.status());
  *response = std::move(*session);
  return grpc::Status::OK;
}

grpc::Status ControlService::ListSessions(grpc::ServerContext* /*context*/,
                                          const v1::ListSessionsRequest* request,
                                          v1::ListSessionsResponse* response) {
  CatalogueFilter filter;
  if (grpc::Status st = ParseCatalogueFilter(*request, &filter); !st.ok()) return st;
  const std::uint32_t page_size =
      request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);
  Result<SessionPage> page = catalogue_.ListSessions(filter, request->page_token(), page_size);
  if (!page.ok()) return ToGrpcStatus(page.status());
  response->mutable_sessions()->Reserve(static_cast<int>(page->sessions.size()));
  for (v1::Session& s : page->sessions) *response->add_sessions() = std::move(s);
  response->set_next_page_token(std::move(page->next_page_token));
  return grpc::Status::OK;
}

grpc::Status ControlService::ListSessionEvents(grpc::ServerContext* /*context*/,
                                               const v1::ListSessionEventsRequest* request,
                                               v1::ListSessionEventsResponse* response) {
  SessionId id = 0;
  if (grpc::Status st = ParseSessionIdField(request->session_id(), "session_id", &id); !st.ok()) {
    return st;
  }
  Result<std::vector<storage::SessionEventRecord>> events =
      catalogue_.reader().ListSessionEvents(id);
  if (!events.ok()) return ToGrpcStatus(events.status());
  response->mutable_events()->Reserve(static_cast<int>(events->size()));
  for (const storage::SessionEventRecord& e : *events)
    *response->add_events() = ToProtoStateEvent(e);
  return grpc::Status::OK;
}

grpc::Status ControlService::WhoAmI(grpc::ServerContext* context,
                                    const v1::WhoAmIRequest* /*request*/, v1::Caller* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  response->set_name(caller.name);
  response->set_role(RoleName(caller.role));
  response->set_server(program_);
  return grpc::Status::OK;
}

}  // namespace brdf::daemon
