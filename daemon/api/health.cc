#include "daemon/api/health.h"

namespace brdf::daemon {
namespace {

using grpc::health::v1::HealthCheckResponse;

}  // namespace

HealthService::HealthService(const StopSignal& stopping, StreamRegistry& streams)
    : stopping_(stopping), streams_(streams) {}

void HealthService::ServeOn(ControlLoop& loop) {
  using grpc::health::v1::HealthCheckRequest;
  loop.Add<HealthCheckRequest, HealthCheckResponse>(
      [this](grpc::ServerContext* c, HealthCheckRequest* r,
             grpc::ServerAsyncResponseWriter<HealthCheckResponse>* w,
             grpc::ServerCompletionQueue* q, void* tag) { RequestCheck(c, r, w, q, q, tag); },
      [this](grpc::ServerContext* c, const HealthCheckRequest* r, HealthCheckResponse* out) {
        return Check(c, r, out);
      });
}

void HealthService::SetServingStatus(const std::string& service, bool serving) {
  {
    MutexLock lock(mu_);
    serving_[service] = serving;
    ++version_;
  }
  changed_.NotifyAll();
}

void HealthService::SetServingStatus(bool serving) {
  {
    MutexLock lock(mu_);
    for (auto& [name, value] : serving_) value = serving;
    ++version_;
  }
  changed_.NotifyAll();
}

HealthService::Status HealthService::StatusLocked(const std::string& service) const {
  auto it = serving_.find(service);
  if (it == serving_.end()) return HealthCheckResponse::SERVICE_UNKNOWN;
  return it->second ? HealthCheckResponse::SERVING : HealthCheckResponse::NOT_SERVING;
}

grpc::Status HealthService::Check(grpc::ServerContext* /*context*/,
                                  const grpc::health::v1::HealthCheckRequest* request,
                                  HealthCheckResponse* response) {
  MutexLock lock(mu_);
  const Status status = StatusLocked(request->service());
  if (status == HealthCheckResponse::SERVICE_UNKNOWN) {
    std::string known;  // the services SetServingStatus named, "" (the server) first
    for (const auto& entry : serving_) {
      const std::string& name = entry.first;
      known +=
          (known.empty() ? "" : ", ") + (name.empty() ? std::string("\"\" (the server)") : name);
    }
    if (known.empty()) known = "none yet (brdfd is starting)";
    return {grpc::StatusCode::NOT_FOUND, "health: no service \"" +
                                             PrintablePrefix(request->service()) +
                                             "\"; ask for one of: " + known};
  }
  response->set_status(status);
  return grpc::Status::OK;
}

grpc::Status HealthService::Watch(grpc::ServerContext* context,
                                  const grpc::health::v1::HealthCheckRequest* request,
                                  grpc::ServerWriter<HealthCheckResponse>* writer) {
  std::unique_ptr<StreamRegistry::Slot> slot;
  if (grpc::Status st = streams_.Open(*context, nullptr, "health Watch", &slot); !st.ok()) {
    return st;
  }
  MutexLock lock(mu_);
  std::uint64_t sent_version = version_;
  Status sent = StatusLocked(request->service());
  for (;;) {
    HealthCheckResponse response;
    response.set_status(sent);
    lock.Unlock();
    if (!slot->Write(writer, response)) return grpc::Status::OK;  // the client went away
    lock.Lock();
    // Until the status changes (a new version may leave it as it was: not sent again).
    for (;;) {
      // A change first: at shutdown the NOT_SERVING set just before Stop() still goes out.
      if (version_ != sent_version) {
        sent_version = version_;
        if (StatusLocked(request->service()) != sent) break;
      }
      if (context->IsCancelled()) return grpc::Status::OK;
      if (stopping_.stopped()) {
        return {grpc::StatusCode::UNAVAILABLE, "health: brdfd is shutting down"};
      }
      // The synchronous API has no wake-up for a client that went away: look now and then.
      changed_.WaitFor(mu_, kStreamPollInterval);
    }
    sent = StatusLocked(request->service());
  }
}

}  // namespace brdf::daemon
