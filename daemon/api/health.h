// The standard health service (grpc.health.v1.Health, proto/grpc/health/v1/health.proto): Check
// answers a service's status now, Watch streams it and each change. Known services: "" (the
// server as a whole) and whatever SetServingStatus named. No token is needed (probes have none).
//
// brdfd serves this itself, on the synchronous API, rather than enabling gRPC's built-in health
// service: that one runs on the callback API, whose threads (two or more, polling the same
// connections as everyone) come with it, and on a 2-core machine they stood between Interpolate's
// loop thread and its calls (interpolate_loop.h).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/mutex.h"
#include "daemon/api/common.h"
#include "daemon/rpc/control_loop.h"
#include "daemon/rpc/stream_registry.h"
#include "grpc/health/v1/health.grpc.pb.h"

namespace brdf::daemon {

class HealthService final
    : public grpc::health::v1::Health::WithAsyncMethod_Check<grpc::health::v1::Health::Service> {
 public:
  // `stopping` ends Watch streams; it must outlive the service.
  HealthService(const StopSignal& stopping, StreamRegistry& streams);

  // Check is served by `loop` (control_loop.h), apart from the streams; Watch by the pool.
  // Before the server is built.
  void ServeOn(ControlLoop& loop);

  // Sets one service's status ("" is the server as a whole), waking its watchers.
  void SetServingStatus(const std::string& service, bool serving);
  // Sets every known service's status at once (shutdown: all NOT_SERVING).
  void SetServingStatus(bool serving);

  grpc::Status Check(grpc::ServerContext* context,
                     const grpc::health::v1::HealthCheckRequest* request,
                     grpc::health::v1::HealthCheckResponse* response) override;
  grpc::Status Watch(grpc::ServerContext* context,
                     const grpc::health::v1::HealthCheckRequest* request,
                     grpc::ServerWriter<grpc::health::v1::HealthCheckResponse>* writer) override;

 private:
  using Status = grpc::health::v1::HealthCheckResponse::ServingStatus;
  // The status of `service` (SERVICE_UNKNOWN when not known), mu_ held.
  Status StatusLocked(const std::string& service) const REQUIRES(mu_);

  const StopSignal& stopping_;
  StreamRegistry& streams_;
  mutable Mutex mu_;
  CondVar changed_;
  std::map<std::string, bool> serving_ GUARDED_BY(mu_);  // by service name
  std::uint64_t version_ GUARDED_BY(mu_) = 0;            // bumped at each change, for watchers
};

}  // namespace brdf::daemon
