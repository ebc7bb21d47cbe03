#include "storage/session_readings.h"

#include "core/plan/plan_json.h"
#include "core/plan/sample.h"

namespace brdf::storage {

Reading ToReading(const ReadingRecord& r) {
  Reading out;
  out.id = r.id;
  out.kind = r.kind;
  out.pose = r.pose;
  out.directions = r.directions;
  out.spectrum = Spectrum{r.grid, r.spectrum};
  out.quality_code = r.quality_code;
  out.flagged = r.flagged;
  out.integration_ms = r.integration_ms;
  out.integration_note = IntegrationNoteOf(r.note);
  out.reference_id = r.reference_reading_id;
  out.dark_id = r.dark_reading_id;
  return out;
}

namespace {

// The session's record as a SessionReadings without readings.
Result<SessionReadings> LoadSessionRecord(SessionReader& reader, std::int64_t session_id) {
  Result<SessionRecord> record = reader.GetSession(session_id);
  if (!record.ok()) {
    if (record.status().code() == StatusCode::kNotFound) {
      return NotFound("unknown session " + std::to_string(session_id) +
                      ": list the sessions with `brdfctl list`");
    }
    return record.status();
  }
  SessionReadings session;
  session.id = record->id;
  session.name = record->name;
  session.white_reflectance = record->white_reflectance;
  if (Result<v1::Plan> plan = plan::ParsePlanJson(record->plan_json); plan.ok()) {
    session.white_reflectance_spectrum = plan::WhiteReflectanceSpectrumOf(*plan);
  } else {
    return Internal("session " + std::to_string(session_id) +
                    ": its stored plan does not parse: " + plan.status().message());
  }
  return session;
}

// Readings asked of a SessionReader per page.
constexpr int kReadingsPerPage = 4096;

}  // namespace

Result<SessionReadings> LoadSessionReadings(SessionReader& reader, std::int64_t session_id) {
  BRDF_ASSIGN_OR_RETURN(SessionReadings session, LoadSessionRecord(reader, session_id));
  for (std::int64_t after = 0;;) {
    BRDF_ASSIGN_OR_RETURN(std::vector<ReadingRecord> page,
                          reader.GetReadings(session_id, after, kReadingsPerPage));
    for (const ReadingRecord& r : page) session.readings.push_back(ToReading(r));
    if (page.size() < static_cast<std::size_t>(kReadingsPerPage)) break;
    after = page.back().id;
  }
  return session;
}

}  // namespace brdf::storage
