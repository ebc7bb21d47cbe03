// SessionStore's side of shipping to the lab archive: the outbox and marks of schema v3 (and the
// events mark of v4, the adaptive rounds of v6; schema.md, archive/schema.md). The archive side is
// archive_writer.h.
#include <set>
#include <string>
#include <utility>

#include "core/status.h"
#include "storage/session_rows.h"
#include "storage/session_store.h"

namespace brdf::storage {
namespace {

Result<std::int64_t> Mark(Database& db, std::string_view name) {
  return db.QueryInt64("SELECT value FROM archive_marks WHERE name = '" + std::string(name) + "'");
}

// The uuid of each session in `ids` not yet in `uuids`.
Status FillUuids(Database& db, const std::set<std::int64_t>& ids,
                 std::map<std::int64_t, std::string>& uuids) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT uuid FROM sessions WHERE id = ?"));
  for (std::int64_t id : ids) {
    if (uuids.count(id) != 0) continue;
    st.Bind(1, id);
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (row) uuids[id] = st.Text(0);
    st.Reset();
  }
  return Status::Ok();
}

// Changes noted in the outbox: which sessions, which sessions with all their steps, which steps.
struct OutboxChanges {
  std::set<std::int64_t> sessions, all_steps;
  std::set<std::int64_t> budgets;  // sessions whose readings' budgets were replaced
  std::set<std::pair<std::int64_t, int>> steps;
  int count = 0;  // outbox entries read
};

// Up to max_changes outbox entries, oldest first; batch.outbox_through becomes the last.
Status ReadOutbox(Database& db, int max_changes, OutboxChanges& changes, ShipBatch& batch) {
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("SELECT seq, session_id, step_index FROM archive_outbox "
                                   "ORDER BY seq LIMIT ?"));
  st.Bind(1, max_changes);
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    ++changes.count;
    batch.outbox_through = st.Int64(0);
    const std::int64_t session = st.Int64(1);
    changes.sessions.insert(session);
    if (st.IsNull(2)) continue;
    if (st.Int64(2) == kOutboxBudgetsReplaced) {
      changes.budgets.insert(session);
    } else if (st.Int64(2) < 0) {
      changes.all_steps.insert(session);
    } else {
      changes.steps.insert({session, st.Int(2)});
    }
  }
  return Status::Ok();
}

// The changed sessions' rows (those still present) and their uuids.
Status ReadChangedSessions(Database& db, const std::string& path,
                           const std::set<std::int64_t>& sessions, ShipBatch& batch) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT " + std::string(kSessionColumns) +
                                                 " FROM sessions WHERE id = ?"));
  for (std::int64_t id : sessions) {
    st.Bind(1, id);
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (row) {
      BRDF_ASSIGN_OR_RETURN(SessionRecord s, ReadSession(st, path));
      batch.uuids[s.id] = s.uuid;
      batch.sessions.push_back(std::move(s));
    }
    st.Reset();
  }
  return Status::Ok();
}

// The changed steps: every step of the sessions in all_steps, then each other changed step.
Status ReadChangedSteps(Database& db, const std::string& path, const OutboxChanges& changes,
                        ShipBatch& batch) {
  BRDF_ASSIGN_OR_RETURN(Statement all,
                        db.Prepare("SELECT " + std::string(kStepColumns) +
                                   " FROM steps WHERE session_id = ? ORDER BY step_index"));
  for (std::int64_t id : changes.all_steps) {
    all.Bind(1, id);
    while (true) {
      BRDF_ASSIGN_OR_RETURN(bool row, all.Step());
      if (!row) break;
      BRDF_ASSIGN_OR_RETURN(StepRecord s, ReadStep(all, path));
      batch.steps.push_back(std::move(s));
    }
    all.Reset();
  }
  BRDF_ASSIGN_OR_RETURN(Statement one,
                        db.Prepare("SELECT " + std::string(kStepColumns) +
                                   " FROM steps WHERE session_id = ? AND step_index = ?"));
  for (const auto& [id, index] : changes.steps) {
    if (changes.all_steps.count(id) != 0) continue;
    one.Bind(1, id).Bind(2, index);
    BRDF_ASSIGN_OR_RETURN(bool row, one.Step());
    if (row) {
      BRDF_ASSIGN_OR_RETURN(StepRecord s, ReadStep(one, path));
      batch.steps.push_back(std::move(s));
    }
    one.Reset();
  }
  return Status::Ok();
}

// The rounds the batch's steps begin (a round's steps were noted in the outbox when it was stored,
// its first among them), and every round of the sessions shipped with all their steps: a round
// reaches the archive in the same transaction as its first step.
Status ReadChangedRounds(Database& db, const OutboxChanges& changes, ShipBatch& batch) {
  const std::string select =
      "SELECT " + std::string(kRoundColumns) + " FROM adaptive_rounds WHERE session_id = ?";
  BRDF_ASSIGN_OR_RETURN(Statement all, db.Prepare(select + " ORDER BY round"));
  BRDF_ASSIGN_OR_RETURN(Statement one, db.Prepare(select + " AND first_step = ?"));
  auto read = [&batch](Statement& st) -> Status {
    while (true) {
      BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
      if (!row) break;
      BRDF_ASSIGN_OR_RETURN(RoundRecord r, ReadRound(st));
      batch.rounds.push_back({std::move(r)});
    }
    st.Reset();
    return Status::Ok();
  };
  for (std::int64_t id : changes.all_steps) {
    all.Bind(1, id);
    BRDF_RETURN_IF_ERROR(read(all));
  }
  for (const auto& [id, index] : changes.steps) {
    if (changes.all_steps.count(id) != 0) continue;
    one.Bind(1, id).Bind(2, index);
    BRDF_RETURN_IF_ERROR(read(one));
  }
  return Status::Ok();
}

// Rounds stored before the shipper sent them (a brdfd older than archive schema v5) reach the
// archive once: the sessions that have rounds are queued whole, the first time shipping is on
// with this brdfd, and the mark 'rounds' says it was done. `queued_all`: every session was just
// queued (shipping was off), so only the mark is set.
Status QueueStoredRoundsOnce(Database& db, bool queued_all, const std::string& what) {
  BRDF_ASSIGN_OR_RETURN(std::int64_t done,
                        db.QueryInt64("SELECT count(*) FROM archive_marks WHERE name = 'rounds'"));
  if (done != 0) return Status::Ok();
  if (!queued_all) {
    BRDF_RETURN_IF_ERROR(db.Exec("INSERT INTO archive_outbox (session_id, step_index) "
                                 "SELECT DISTINCT session_id, -1 FROM adaptive_rounds "
                                 "ORDER BY session_id")
                             .WithContext(what));
  }
  return db.Exec("INSERT INTO archive_marks (name, value) VALUES ('rounds', 1)").WithContext(what);
}

// The readings at or below the readings mark (the archive has them) of the sessions whose budgets
// were replaced, with their budgets as they are now.
Status ReadRebudgeted(Database& db, const std::string& path, const std::set<std::int64_t>& sessions,
                      ShipBatch& batch) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT " + std::string(kReadingColumns) +
                                                 " FROM " + std::string(kReadingsWithUncertainty) +
                                                 " WHERE session_id = ? AND id <= ? ORDER BY id"));
  for (std::int64_t id : sessions) {
    st.Bind(1, id).Bind(2, batch.readings_through);
    while (true) {
      BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
      if (!row) break;
      BRDF_ASSIGN_OR_RETURN(ReadingRecord r, ReadReading(st, path));
      if (r.uncertainty.has_value()) batch.rebudgeted.push_back(std::move(r));
    }
    st.Reset();
  }
  return Status::Ok();
}

// Up to `limit` readings past batch.readings_through, which moves to the last.
Status ReadNewReadings(Database& db, const std::string& path, int limit, ShipBatch& batch,
                       std::set<std::int64_t>& named) {
  BRDF_ASSIGN_OR_RETURN(Statement st, db.Prepare("SELECT " + std::string(kReadingColumns) +
                                                 " FROM " + std::string(kReadingsWithUncertainty) +
                                                 " WHERE id > ? ORDER BY id LIMIT ?"));
  st.Bind(1, batch.readings_through).Bind(2, limit);
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(ReadingRecord r, ReadReading(st, path));
    batch.readings_through = r.id;
    named.insert(r.session_id);
    batch.readings.push_back(std::move(r));
  }
  return Status::Ok();
}

// Up to `limit` devices past batch.devices_through, which moves to the last.
Status ReadNewDevices(Database& db, int limit, ShipBatch& batch, std::set<std::int64_t>& named) {
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("SELECT id, session_id, kind, model, serial, first_seen "
                                   "FROM devices WHERE id > ? ORDER BY id LIMIT ?"));
  st.Bind(1, batch.devices_through).Bind(2, limit);
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    batch.devices.push_back(DeviceRecord{st.Int64(0), st.OptionalInt64(1), st.Text(2), st.Text(3),
                                         st.Text(4), st.Double(5)});
    batch.devices_through = batch.devices.back().id;
    if (batch.devices.back().session_id) named.insert(*batch.devices.back().session_id);
  }
  return Status::Ok();
}

// Up to `limit` audit entries past batch.audit_through, which moves to the last.
Status ReadNewAudit(Database& db, int limit, ShipBatch& batch, std::set<std::int64_t>& named) {
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("SELECT id, at, role, actor, action, session_id, detail "
                                   "FROM audit WHERE id > ? ORDER BY id LIMIT ?"));
  st.Bind(1, batch.audit_through).Bind(2, limit);
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    batch.audit.push_back(AuditRecord{st.Int64(0), st.Double(1), st.Text(2), st.Text(3), st.Text(4),
                                      st.OptionalInt64(5), st.Text(6)});
    batch.audit_through = batch.audit.back().id;
    if (batch.audit.back().session_id) named.insert(*batch.audit.back().session_id);
  }
  return Status::Ok();
}

// Up to `limit` session events past batch.events_through, which moves to the last.
Status ReadNewEvents(Database& db, const std::string& path, int limit, ShipBatch& batch,
                     std::set<std::int64_t>& named) {
  BRDF_ASSIGN_OR_RETURN(Statement st,
                        db.Prepare("SELECT " + std::string(kEventColumns) +
                                   " FROM session_events WHERE id > ? ORDER BY id LIMIT ?"));
  st.Bind(1, batch.events_through).Bind(2, limit);
  while (true) {
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (!row) break;
    BRDF_ASSIGN_OR_RETURN(SessionEventRecord e, ReadEvent(st, path));
    batch.events_through = e.id;
    named.insert(e.session_id);
    batch.events.push_back(std::move(e));
  }
  return Status::Ok();
}

}  // namespace

Status SessionStore::SetArchiveShipping(bool enabled) {
  const std::string what =
      enabled ? "turning on shipping to the archive" : "turning off shipping to the archive";
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_ASSIGN_OR_RETURN(std::int64_t was, Mark(db, "enabled"));
  if (was == 1 && enabled) {
    BRDF_RETURN_IF_ERROR(QueueStoredRoundsOnce(db, /*queued_all=*/false, what));
    return tx.Commit().WithContext(what);
  }
  if ((was == 1) == enabled) return Status::Ok();
  if (enabled) {
    BRDF_RETURN_IF_ERROR(QueueStoredRoundsOnce(db, /*queued_all=*/true, what));
    BRDF_RETURN_IF_ERROR(db.Exec("INSERT INTO archive_outbox (session_id, step_index) "
                                 "SELECT id, -1 FROM sessions ORDER BY id")
                             .WithContext(what));
  } else {
    BRDF_RETURN_IF_ERROR(db.Exec("DELETE FROM archive_outbox").WithContext(what));
  }
  BRDF_RETURN_IF_ERROR(db.Exec(std::string("UPDATE archive_marks SET value = ") +
                               (enabled ? "1" : "0") + " WHERE name = 'enabled'")
                           .WithContext(what));
  return tx.Commit().WithContext(what);
}

Result<ShipBatch> SessionStore::NextShipBatch(int max_readings, int max_changes) {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  ShipBatch batch;

  OutboxChanges changes;
  BRDF_RETURN_IF_ERROR(ReadOutbox(*db, max_changes, changes, batch));
  BRDF_RETURN_IF_ERROR(ReadChangedSessions(*db, path_, changes.sessions, batch));
  BRDF_RETURN_IF_ERROR(ReadChangedSteps(*db, path_, changes, batch));
  BRDF_RETURN_IF_ERROR(ReadChangedRounds(*db, changes, batch));

  BRDF_ASSIGN_OR_RETURN(batch.readings_through, Mark(*db, "readings"));
  BRDF_ASSIGN_OR_RETURN(batch.devices_through, Mark(*db, "devices"));
  BRDF_ASSIGN_OR_RETURN(batch.audit_through, Mark(*db, "audit"));
  BRDF_ASSIGN_OR_RETURN(batch.events_through, Mark(*db, "events"));
  BRDF_RETURN_IF_ERROR(ReadRebudgeted(*db, path_, changes.budgets, batch));
  // Rows may name sessions not shipped yet: next time.
  if (changes.count >= max_changes) return batch;

  // Rows past the marks, and the sessions they name.
  std::set<std::int64_t> named;
  BRDF_RETURN_IF_ERROR(ReadNewReadings(*db, path_, max_readings, batch, named));
  BRDF_RETURN_IF_ERROR(ReadNewDevices(*db, max_readings, batch, named));
  BRDF_RETURN_IF_ERROR(ReadNewAudit(*db, max_readings, batch, named));
  BRDF_RETURN_IF_ERROR(ReadNewEvents(*db, path_, max_readings, batch, named));
  BRDF_RETURN_IF_ERROR(FillUuids(*db, named, batch.uuids));
  return batch;
}

Status SessionStore::MarkShipped(const ShipBatch& batch) {
  const std::string what = "recording what the archive has";
  MutexLock lock(write_mu_);
  Database& db = *writer_;
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::Begin(db));
  BRDF_ASSIGN_OR_RETURN(
      Statement st, db.Prepare("UPDATE archive_marks SET value = max(value, ?) WHERE name = ?"));
  for (const auto& [name, value] :
       {std::pair<const char*, std::int64_t>{"readings", batch.readings_through},
        {"devices", batch.devices_through},
        {"audit", batch.audit_through},
        {"events", batch.events_through}}) {
    st.Bind(1, value).Bind(2, name);
    BRDF_RETURN_IF_ERROR(st.Run().WithContext(what));
    st.Reset();
  }
  if (batch.outbox_through > 0) {
    BRDF_ASSIGN_OR_RETURN(Statement del, db.Prepare("DELETE FROM archive_outbox WHERE seq <= ?"));
    del.Bind(1, batch.outbox_through);
    BRDF_RETURN_IF_ERROR(del.Run().WithContext(what));
  }
  return tx.Commit().WithContext(what);
}

Result<ShipLag> SessionStore::ShippingLag() {
  BRDF_ASSIGN_OR_RETURN(ReaderPool::Lease db, readers_->Acquire());
  BRDF_ASSIGN_OR_RETURN(Transaction tx, Transaction::BeginRead(*db));
  ShipLag lag;
  BRDF_ASSIGN_OR_RETURN(lag.shipped_readings, Mark(*db, "readings"));
  const std::string above = " FROM readings WHERE id > " + std::to_string(lag.shipped_readings);
  BRDF_ASSIGN_OR_RETURN(lag.readings, db->QueryInt64("SELECT count(*)" + above));
  if (lag.readings > 0) {
    BRDF_ASSIGN_OR_RETURN(Statement st,
                          db->Prepare("SELECT recorded_at" + above + " ORDER BY id LIMIT 1"));
    BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
    if (row) lag.oldest_unshipped = st.Double(0);
  }
  BRDF_ASSIGN_OR_RETURN(lag.pending_changes, db->QueryInt64("SELECT count(*) FROM archive_outbox"));
  BRDF_ASSIGN_OR_RETURN(std::int64_t events_mark, Mark(*db, "events"));
  BRDF_ASSIGN_OR_RETURN(lag.events,
                        db->QueryInt64("SELECT count(*) FROM session_events WHERE id > " +
                                       std::to_string(events_mark)));
  return lag;
}

}  // namespace brdf::storage
