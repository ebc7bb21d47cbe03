#include "daemon/api/data.h"

#include <string>
#include <vector>

#include "daemon/api/stream_readings.h"

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
  return Serve(*context, *request, "StreamReadings",
               [&](StreamReadingsCall& call, const ReadingSource& source) {
                 return StreamSessionReadings(*context, *request, call, source, writer);
               });
}

grpc::Status DataService::StreamReadingPoints(grpc::ServerContext* context,
                                              const v1::StreamReadingsRequest* request,
                                              grpc::ServerWriter<v1::ReadingPoints>* writer) {
  return Serve(*context, *request, "StreamReadingPoints",
               [&](StreamReadingsCall& call, const ReadingSource& source) {
                 return StreamSessionReadingPoints(*context, *request, call, source, writer);
               });
}

grpc::Status DataService::Serve(grpc::ServerContext& context,
                                const v1::StreamReadingsRequest& request, const char* rpc,
                                const ReadingStreamBody& body) {
  StreamReadingsCall call;
  if (grpc::Status st = CheckStreamReadings(context, request, rpc, auth_, streams_, &call);
      !st.ok()) {
    return st;
  }
  storage::SessionStore& store = *manager_.store();
  Result<storage::SessionRecord> session = store.GetSession(call.session);
  if (!session.ok()) return ToGrpcStatus(session.status());

  std::uint64_t generation = 0;
  ReadingSource source;
  source.reader = &store;
  // The state BEFORE the page: a session that had ended before the page was read has no reading
  // after it, so an empty page then really is the end.
  source.ended = [&]() -> Result<bool> {
    Result<storage::SessionRecord> now = store.GetSession(call.session);
    if (!now.ok()) return now.status();
    generation = Generation();
    return IsTerminal(now->state);
  };
  source.wait = [&] {
    if (stopping_.stopped()) return true;
    WaitForReading(generation, kStreamPollInterval);
    return false;
  };
  // Labels and averaging are fixed at submission.
  source.extras = [&] {
    std::uint32_t averages = 0;
    if (Result<std::shared_ptr<const SessionPlan>> plan = manager_.Plan(call.session); plan.ok()) {
      averages = (*plan)->plan.measurement().averages();
    }
    return ReadingExtrasOf(store, call.session, averages);
  };
  return body(call, source);
}

}  // namespace brdf::daemon
