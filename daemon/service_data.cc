#include "daemon/service_data.h"

#include <set>
#include <string>
#include <vector>

namespace brdf::daemon {

DataService::DataService(SessionManager& manager, const Authenticator& auth,
                         const StopSignal& stopping, StreamRegistry& streams)
    : manager_(manager), auth_(auth), stopping_(stopping), streams_(streams) {
  listener_ = manager_.AddReadingListener([this](SessionId, const storage::ReadingRecord&) {
    {
      MutexLock lock(mu_);
      ++generation_;
    }
    cv_.NotifyAll();
  });
}

DataService::~DataService() {
  manager_.RemoveReadingListener(listener_);
}

std::uint64_t DataService::Generation() const {
  MutexLock lock(mu_);
  return generation_;
}

void DataService::WaitForReading(std::uint64_t seen, std::chrono::steady_clock::duration d) const {
  MutexLock lock(mu_);
  cv_.WaitFor(mu_, d, [&]() REQUIRES(mu_) { return generation_ != seen || stopping_.stopped(); });
}

grpc::Status DataService::StreamReadings(grpc::ServerContext* context,
                                         const v1::StreamReadingsRequest* request,
                                         grpc::ServerWriter<v1::Reading>* writer) {
  Caller caller;
  if (grpc::Status st = auth_.Authorize(*context, Access::kRead, "StreamReadings", &caller);
      !st.ok()) {
    return st;
  }
  std::unique_ptr<StreamRegistry::Slot> slot;
  if (grpc::Status st = streams_.Open(*context, &caller, "StreamReadings", &slot); !st.ok()) {
    return st;
  }
  SessionId id = 0;
  if (grpc::Status st = ParseSessionIdField(request->session_id(), "session_id", &id); !st.ok()) {
    return st;
  }
  std::set<storage::ReadingKind> kinds;
  for (int i = 0; i < request->kinds_size(); ++i) {
    switch (request->kinds(i)) {
      case v1::READING_KIND_SAMPLE:
        kinds.insert(storage::ReadingKind::kSample);
        break;
      case v1::READING_KIND_REFERENCE:
        kinds.insert(storage::ReadingKind::kReference);
        break;
      case v1::READING_KIND_DARK:
        kinds.insert(storage::ReadingKind::kDark);
        break;
      default:
        return InvalidField("kinds[" + std::to_string(i) + "]",
                            "unknown reading kind " + std::to_string(request->kinds(i)) +
                                "; use READING_KIND_SAMPLE, _REFERENCE or _DARK");
    }
  }
  if (request->after_id() < 0) {
    return InvalidField("after_id", "must be ≥ 0 (got " + std::to_string(request->after_id()) +
                                        "); 0 starts from the first reading");
  }

  storage::SessionStore& store = *manager_.store();
  Result<storage::SessionRecord> session = store.GetSession(id);
  if (!session.ok()) return ToGrpcStatus(session.status());

  // Labels and averaging are fixed at submission: read them once.
  ReadingExtras extras;
  if (Result<std::vector<storage::StepRecord>> steps = store.GetSteps(id); steps.ok()) {
    for (const storage::StepRecord& step : *steps) extras.step_labels[step.step_index] = step.label;
  }
  if (Result<std::shared_ptr<const SessionPlan>> plan = manager_.Plan(id);
      plan.ok() && (*plan)->plan.measurement().averages() > 0) {
    extras.averages = (*plan)->plan.measurement().averages();
  }

  std::int64_t last = request->after_id();
  for (;;) {
    if (context->IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "StreamReadings: cancelled by the client");
    }
    // Read the state BEFORE the page: a session that had ended before the page was read has no
    // reading after it, so an empty page then really is the end.
    bool ended = !request->follow();
    if (!ended) {
      Result<storage::SessionRecord> now = store.GetSession(id);
      if (!now.ok()) return ToGrpcStatus(now.status());
      ended = IsTerminal(now->state);
    }
    const std::uint64_t generation = Generation();
    Result<std::vector<storage::ReadingRecord>> page = store.GetReadings(id, last, kPageSize);
    if (!page.ok()) return ToGrpcStatus(page.status());
    for (const storage::ReadingRecord& r : *page) {
      last = r.id;
      if (!kinds.empty() && kinds.count(r.kind) == 0) continue;
      if (!slot->Write(writer, ToProtoReading(r, extras))) {
        return grpc::Status(grpc::StatusCode::CANCELLED, "StreamReadings: the client went away");
      }
    }
    if (static_cast<int>(page->size()) == kPageSize) continue;  // more stored: next page now
    if (ended) return grpc::Status::OK;
    if (stopping_.stopped()) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          "StreamReadings: the daemon is shutting down; resume with after_id = " +
                              std::to_string(last) + " once it is back");
    }
    WaitForReading(generation, kStreamPollInterval);
  }
}

}  // namespace brdf::daemon
