#include "tools/brdf-export/session_source.h"

#include <filesystem>
#include <system_error>

namespace brdf::export_tool {

Result<std::unique_ptr<storage::SessionStore>> OpenExistingStore(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return NotFound("no database at " + path +
                    ": give the brdfd database file (the daemon's [storage] database setting, "
                    "/var/lib/brdfd/brdfd.db by default)");
  }
  return storage::SessionStore::Open(path);
}

exports::Reading ToExportReading(const storage::ReadingRecord& r) {
  exports::Reading out;
  out.id = r.id;
  switch (r.kind) {
    case storage::ReadingKind::kSample:
      out.kind = exports::ReadingKind::kSample;
      break;
    case storage::ReadingKind::kReference:
      out.kind = exports::ReadingKind::kReference;
      break;
    case storage::ReadingKind::kDark:
      out.kind = exports::ReadingKind::kDark;
      break;
  }
  out.pose = r.pose;
  out.directions = r.directions;
  out.spectrum = Spectrum{r.grid, r.spectrum};
  out.quality_code = r.quality_code;
  out.flagged = r.flagged;
  out.integration_ms = r.integration_ms;
  out.reference_id = r.reference_reading_id;
  out.dark_id = r.dark_reading_id;
  return out;
}

Result<exports::Session> LoadSession(storage::SessionStore& store, std::int64_t session_id) {
  Result<storage::SessionRecord> record = store.GetSession(session_id);
  if (!record.ok()) {
    if (record.status().code() == StatusCode::kNotFound) {
      return NotFound("unknown session " + std::to_string(session_id) + " in " + store.path() +
                      ": list the sessions with `brdfctl list`");
    }
    return record.status();
  }
  exports::Session session;
  session.id = record->id;
  session.name = record->name;
  session.white_reflectance = record->white_reflectance;
  BRDF_RETURN_IF_ERROR(store.ForEachReading(session_id, [&](const storage::ReadingRecord& r) {
    session.readings.push_back(ToExportReading(r));
    return Status::Ok();
  }));
  return session;
}

}  // namespace brdf::export_tool
