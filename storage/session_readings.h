// A stored session handed out as core/readings' values: the session record's ρw and name, and
// every reading (sample, reference, dark) converted from its ReadingRecord. The exports (brdfd's
// Data.Export, brdf-export) load whole sessions so; the daemon's interpolation index converts
// each committed record as it lands. Read-only: only the reader's GetSession and GetReadings are
// called.
#pragma once

#include <cstdint>

#include "core/readings/reading.h"
#include "core/status.h"
#include "core/uncertainty/blend_budget.h"
#include "storage/records.h"
#include "storage/session_reader.h"

namespace brdf::storage {

// One record as a Reading (what the derivation needs; the step, attempts, note, meter serial and
// time stay in the record). With `budgets`, the stored budget of the BRDF is kept in the exports'
// form (Reading::budget, its blend form made by `budgets`: one maker for a session's readings);
// without, Reading::budget is null (the daemon's index keeps the budgets its own way).
Reading ToReading(const ReadingRecord& r, uncertainty::BlendBudgetMaker* budgets = nullptr);

// The session and all its readings, in id order, read a page at a time from any SessionReader
// (the rig's store: brdfd's and brdf-export's exports; the lab archive: brdf-archive's).
// kNotFound for an unknown session (naming it), and the reader's errors.
Result<SessionReadings> LoadSessionReadings(SessionReader& reader, std::int64_t session_id);

}  // namespace brdf::storage
