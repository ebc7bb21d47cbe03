// AuditWriter: the operator's verbs' audit records into the store (issue 40). A verb that changed
// something (a state, a place in the queue, an answered prompt) has its record written before the
// verb returns, like the change itself: what the operator was told happened is on record once the
// reply leaves. A verb that changed nothing (a pause of a paused session) or was refused is
// answered first: its record is queued and written right after by the writer's own thread, in
// order (a record written now first waits for those queued), with the call's time; Drain (the
// destructor, the manager's shutdown) writes what is queued. A crash in between loses only the
// record of a call that changed nothing.
//
// A record naming a session the store does not know (a verb on a missing session) is kept
// without the session, its id in the detail.
#pragma once

#include <deque>
#include <functional>
#include <string>
#include <thread>

#include "core/mutex.h"
#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::daemon {

class AuditWriter {
 public:
  // `store` must outlive the writer. `now` gives the time a queued record is stamped with.
  AuditWriter(storage::SessionStore& store, std::function<storage::UnixSeconds()> now);
  ~AuditWriter();
  AuditWriter(const AuditWriter&) = delete;
  AuditWriter& operator=(const AuditWriter&) = delete;

  // Written now, after what is queued (durable when it returns; a failure is logged).
  void Write(storage::AuditRecord record);
  // Queued, stamped with now(), written by the writer's thread.
  void WriteLater(storage::AuditRecord record);
  // Waits until every queued record was written.
  void Drain();

 private:
  void Run();
  void Append(storage::AuditRecord record);

  storage::SessionStore& store_;
  const std::function<storage::UnixSeconds()> now_;
  Mutex mu_;
  CondVar cv_;
  std::deque<storage::AuditRecord> queue_ GUARDED_BY(mu_);
  bool writing_ GUARDED_BY(mu_) = false;
  bool stopping_ GUARDED_BY(mu_) = false;
  std::thread thread_;
};

}  // namespace brdf::daemon
