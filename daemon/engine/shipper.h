// ArchiveShipper: ships everything the rig records to the lab archive (PostgreSQL) on a thread of
// its own, when [archive] is configured. The rig's SQLite stays the durable record: the shipper
// reads batches from it (SessionStore::NextShipBatch), writes each batch to the archive in one
// transaction of idempotent upserts (storage/archive/writer.h), and only then moves the rig's
// marks (SessionStore::MarkShipped). A crash of either side at any moment leaves every reading in
// the archive exactly once: a batch the archive committed but the rig did not mark is sent again
// and changes nothing.
//
// An adaptive round is shipped with what it meant for the budget as this rig's ListAdaptiveRounds
// answers it (StoredRounds on the rig's description: only the rig can compute it), so that
// brdf-archive answers the same rounds (storage/archive/schema.md, adaptive_rounds).
//
// It never touches the executor's path: recording goes on whatever the archive does (away, slow,
// refusing our password, its disk full). On any archive failure it drops the connection, waits
// retry, reconnects (re-reading the credentials file, so fixing it needs no restart) and
// continues from the marks. Snapshot() gives the state and the lag for GetRigStatus.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "brdf/v1/brdf.pb.h"
#include "core/mutex.h"
#include "core/plan/rig_description.h"
#include "core/status.h"
#include "storage/session_store.h"

namespace brdf::daemon {

class ArchiveShipper {
 public:
  struct Options {
    std::string credentials_path;           // file holding the libpq conninfo (never logged)
    std::string rig;                        // this rig's name
    int batch_readings = 200;               // readings per archive transaction
    std::chrono::milliseconds retry{2000};  // wait after a failure
    std::chrono::milliseconds poll{50};     // wait when caught up
    plan::RigDescription rig_description;   // the rig's (the rounds' spend); as the manager's
  };

  // Turns the rig's outbox on and starts the thread. kIoError when the outbox cannot be enabled.
  static Result<std::unique_ptr<ArchiveShipper>> Start(std::shared_ptr<storage::SessionStore> store,
                                                       Options options);
  ~ArchiveShipper();  // Stop()
  ArchiveShipper(const ArchiveShipper&) = delete;
  ArchiveShipper& operator=(const ArchiveShipper&) = delete;

  // Stops the thread (a batch in flight is finished or rolled back by the archive).
  void Stop();
  // State, last problem and lag (readings and seconds behind the rig).
  v1::ArchiveStatus Snapshot() const;

 private:
  ArchiveShipper(std::shared_ptr<storage::SessionStore> store, Options options);
  void Run();
  // Waits `d` or until Stop(); false when stopping.
  bool Wait(std::chrono::milliseconds d);
  void SetState(v1::ArchiveState state, const std::string& detail);

  std::shared_ptr<storage::SessionStore> store_;
  const Options options_;
  mutable Mutex mu_;
  CondVar cv_;
  bool stopping_ GUARDED_BY(mu_) = false;
  v1::ArchiveState state_ GUARDED_BY(mu_) = v1::ARCHIVE_STATE_CONNECTING;
  std::string detail_ GUARDED_BY(mu_);
  std::uint64_t shipped_ GUARDED_BY(mu_) = 0;
  double last_shipped_at_ GUARDED_BY(mu_) = 0;
  std::thread thread_;
};

// GetRigStatus's archive part when [archive] is not configured.
v1::ArchiveStatus ArchiveOffStatus();

}  // namespace brdf::daemon
