// What the rig ships to the lab archive in one transaction (SessionStore::NextShipBatch): the
// current rows of the sessions and steps changed since they were last shipped, the adaptive
// rounds those steps begin, and the readings, devices, audit entries and session events above
// their high-water marks, all read from one snapshot of the rig's database. The marks the batch
// reaches move only once the archive has committed it (SessionStore::MarkShipped).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "storage/records.h"

namespace brdf::storage {

// archive_outbox's step_index for "the session's readings' uncertainty budgets were replaced"
// (-1: every step of the session; NULL: the session's row; ≥ 0: that step).
inline constexpr std::int64_t kOutboxBudgetsReplaced = -2;

// A round of an adaptive session as the archive keeps it (archive schema v5, adaptive_rounds):
// the rig's record and what the round meant for the budget, as the rig's ListAdaptiveRounds
// answers it (daemon/engine/adaptive_rounds.h, StoredRounds: the plan's timing model for real
// devices on the rig's description) -- the rig time and prompts the session had spent when the
// round was chosen, and what the round's own steps cost. NextShipBatch reads the record; the
// shipper, which knows the rig's description, fills the spend before writing.
struct ArchivedRound {
  RoundRecord record;
  double spent_rig_s = 0;
  int spent_prompts = 0;
  double rig_s = 0;
  int prompts = 0;
};

struct ShipBatch {
  std::int64_t outbox_through = 0;  // the last outbox entry covered (0: none)
  std::vector<SessionRecord> sessions;
  std::vector<StepRecord> steps;  // of sessions in `uuids`
  std::vector<ReadingRecord> readings;
  std::vector<DeviceRecord> devices;
  std::vector<AuditRecord> audit;
  std::vector<SessionEventRecord> events;  // (v4) of sessions in `uuids`
  // The rounds whose first step is among `steps` (a round's steps are noted in the outbox when it
  // is stored), every round of a session shipped with all its steps; of sessions in `uuids`.
  std::vector<ArchivedRound> rounds;
  // Readings the archive has already (at or below the readings mark) whose uncertainty budgets the
  // rig replaced since (SessionStore::ReplaceReadingUncertainties, at a session's end): the
  // archive replaces theirs. Sessions in `uuids`.
  std::vector<ReadingRecord> rebudgeted;
  std::int64_t readings_through = 0;  // marks after this batch
  std::int64_t devices_through = 0;
  std::int64_t audit_through = 0;
  std::int64_t events_through = 0;
  std::map<std::int64_t, std::string> uuids;  // session id → uuid, for every session named

  bool empty() const {
    return sessions.empty() && steps.empty() && readings.empty() && devices.empty() &&
           audit.empty() && events.empty() && rebudgeted.empty() && rounds.empty() &&
           outbox_through == 0;
  }
};

// How far the archive is behind the rig.
struct ShipLag {
  std::int64_t readings = 0;          // readings recorded and not yet shipped
  double oldest_unshipped = 0;        // recorded_at of the oldest of them (0 when none)
  std::int64_t shipped_readings = 0;  // the readings mark
  std::int64_t pending_changes = 0;   // outbox entries
  std::int64_t events = 0;            // session events not yet shipped (v4)
};

}  // namespace brdf::storage
