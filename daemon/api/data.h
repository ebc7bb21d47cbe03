// The Data service (brdf.proto): a session's readings, streamed in id order from the store, a
// page at a time (memory bounded by one page whatever the session's size). With `follow` the
// stream stays open and sends readings as they are committed (woken by a SessionManager reading
// listener), until the session ends, the client cancels, or the daemon stops. Its exports to
// files (Export) live in service_export.cc.
#pragma once

#include <cstdint>
#include <memory>

#include "brdf/v1/brdf.grpc.pb.h"
#include "core/mutex.h"
#include "daemon/api/common.h"
#include "daemon/api/stream_readings.h"
#include "daemon/engine/session_manager.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

class DataService final : public v1::Data::Service {
 public:
  // Registers a reading listener on `manager` (removed by the destructor). All three must
  // outlive the service.
  DataService(SessionManager& manager, const Authenticator& auth, const StopSignal& stopping,
              StreamRegistry& streams);
  ~DataService() override;

  grpc::Status StreamReadings(grpc::ServerContext* context,
                              const v1::StreamReadingsRequest* request,
                              grpc::ServerWriter<v1::Reading>* writer) override;
  // The same readings as columns of poses and directions, without spectra.
  grpc::Status StreamReadingPoints(grpc::ServerContext* context,
                                   const v1::StreamReadingsRequest* request,
                                   grpc::ServerWriter<v1::ReadingPoints>* writer) override;

  // A session exported to a file (readings CSV, grid .npy/CSV, MERL .binary), streamed as
  // progress, the file's bytes in chunks, then the report. Defined in service_export.cc.
  grpc::Status Export(grpc::ServerContext* context, const v1::ExportRequest* request,
                      grpc::ServerWriter<v1::ExportChunk>* writer) override;

 private:
  // Both readings streams (`rpc`: which one, for its errors): the request checked, the session
  // looked up, then `body` with the store as the source (following new readings through the
  // listener).
  grpc::Status Serve(grpc::ServerContext& context, const v1::StreamReadingsRequest& request,
                     const char* rpc, const ReadingStreamBody& body);

  // Woken whenever any reading is committed; followers re-read the store then.
  std::uint64_t Generation() const;
  void WaitForReading(std::uint64_t seen, std::chrono::steady_clock::duration d) const;

  SessionManager& manager_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
  StreamRegistry& streams_;
  int listener_ = 0;

  mutable Mutex mu_;
  mutable CondVar cv_;
  std::uint64_t generation_ GUARDED_BY(mu_) = 0;
};

}  // namespace brdf::daemon
