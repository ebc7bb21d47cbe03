// A stored session as core/export's Session: the session record's ρw and name, and every reading
// (sample, reference, dark) copied from storage's ReadingRecords. Read-only use of the store: only
// GetSession and ForEachReading are called.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/export/session_data.h"
#include "core/status.h"
#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::export_tool {

// Opens an EXISTING brdfd database (kNotFound naming the path when there is no file: the store
// itself would create an empty one).
Result<std::unique_ptr<storage::SessionStore>> OpenExistingStore(const std::string& path);

// The session and all its readings. kNotFound for an unknown session (naming it and the
// database), and the store's errors.
Result<exports::Session> LoadSession(storage::SessionStore& store, std::int64_t session_id);

// One record converted.
exports::Reading ToExportReading(const storage::ReadingRecord& r);

}  // namespace brdf::export_tool
