#include "storage/session_rows.h"

#include "core/status.h"
#include "storage/round_picks.h"
#include "storage/spectrum_blob.h"
#include "storage/uncertainty_columns.h"

namespace brdf::storage {

const std::string_view kSessionColumns =
    "id, name, plan_kind, plan_json, state, state_reason, created_at, started_at, finished_at, "
    "created_by_role, total_steps, done_steps, white_reflectance, meter_serial, config_json, "
    "uuid, rig, "
    // The session's grid: its first reading's (readings_by_session finds it).
    "(SELECT wl_start_nm FROM readings WHERE session_id = sessions.id ORDER BY id LIMIT 1), "
    "(SELECT wl_step_nm FROM readings WHERE session_id = sessions.id ORDER BY id LIMIT 1), "
    "(SELECT wl_count FROM readings WHERE session_id = sessions.id ORDER BY id LIMIT 1)";

const std::string_view kStepColumns =
    "session_id, step_index, kind, alpha, beta, gamma, delta, prompt, prompt_kind, "
    "expected_action, target_theta_i, target_phi_i, target_theta_o, target_phi_o, label, state, "
    "note, completed_at";

const std::string_view kReadingColumns =
    "id, session_id, step_index, kind, alpha, beta, gamma, delta, theta_i, phi_i, theta_o, phi_o, "
    "wl_start_nm, wl_step_nm, wl_count, spectrum, quality_code, flagged, integration_ms, attempts, "
    "note, reference_reading_id, dark_reading_id, meter_serial, recorded_at, quantity, value, "
    "combined, independent, components, contributions, not_estimated";

const std::string_view kReadingsWithUncertainty =
    "readings LEFT JOIN reading_uncertainty ON reading_uncertainty.reading_id = readings.id";

const std::string_view kEventColumns = "id, session_id, at, state, reason";

const std::string_view kReadingPointColumns =
    "id, kind, alpha, beta, gamma, delta, theta_i, phi_i, theta_o, phi_o, flagged";

const std::string_view kRoundColumns =
    "session_id, round, first_step, step_count, picks, predicted_gain, uncertainty_left, "
    "readings_used, created_at";

namespace {

std::string SessionName(std::int64_t session) {
  return "session " + std::to_string(session);
}
std::string StepName(std::int64_t session, int step) {
  return "step " + std::to_string(step) + " of session " + std::to_string(session);
}

}  // namespace

Result<SessionRecord> ReadSession(const Statement& st, const std::string& path) {
  SessionRecord s;
  s.id = st.Int64(0);
  s.name = st.Text(1);
  s.plan_kind = st.Text(2);
  s.plan_json = st.Text(3);
  BRDF_ASSIGN_OR_RETURN(s.state,
                        FromColumn(ParseSessionState(st.Text(4)), path, SessionName(s.id)));
  s.state_reason = st.Text(5);
  s.created_at = st.Double(6);
  s.started_at = st.OptionalDouble(7);
  s.finished_at = st.OptionalDouble(8);
  s.created_by_role = st.Text(9);
  s.total_steps = st.Int(10);
  s.done_steps = st.Int(11);
  s.white_reflectance = st.OptionalDouble(12);
  s.meter_serial = st.Text(13);
  s.config_json = st.Text(14);
  s.uuid = st.Text(15);
  s.rig = st.Text(16);
  if (!st.IsNull(19)) {
    s.grid = WavelengthGrid{st.Double(17), st.Double(18), static_cast<std::size_t>(st.Int64(19))};
  }
  return s;
}

Result<SessionEventRecord> ReadEvent(const Statement& st, const std::string& path) {
  SessionEventRecord e;
  e.id = st.Int64(0);
  e.session_id = st.Int64(1);
  e.at = st.Double(2);
  BRDF_ASSIGN_OR_RETURN(
      e.state, FromColumn(ParseSessionState(st.Text(3)), path,
                          "event " + std::to_string(e.id) + " of " + SessionName(e.session_id)));
  e.reason = st.Text(4);
  return e;
}

Result<RoundRecord> ReadRound(const Statement& st) {
  RoundRecord r;
  r.session_id = st.Int64(0);
  r.round = st.Int(1);
  r.first_step = st.Int(2);
  r.step_count = st.Int(3);
  BRDF_ASSIGN_OR_RETURN(r.picks, DecodePicks(st.Text(4)));
  r.predicted_gain = st.Double(5);
  r.uncertainty_left = st.Double(6);
  r.readings_used = st.Int(7);
  r.created_at = st.Double(8);
  return r;
}

Result<StepRecord> ReadStep(const Statement& st, const std::string& path) {
  StepRecord s;
  s.session_id = st.Int64(0);
  s.step_index = st.Int(1);
  const std::string where = StepName(s.session_id, s.step_index);
  BRDF_ASSIGN_OR_RETURN(s.kind, FromColumn(ParseStepKind(st.Text(2)), path, where));
  s.pose = Pose{st.Double(3), st.Double(4), st.Double(5), st.Double(6)};
  s.prompt = st.OptionalText(7);
  s.prompt_kind = st.OptionalText(8);
  s.expected_action = st.OptionalText(9);
  if (!st.IsNull(10)) {
    s.target = Directions{st.Double(10), st.Double(11), st.Double(12), st.Double(13)};
  }
  s.label = st.Text(14);
  BRDF_ASSIGN_OR_RETURN(s.state, FromColumn(ParseStepState(st.Text(15)), path, where));
  s.note = st.OptionalText(16);
  s.completed_at = st.OptionalDouble(17);
  return s;
}

Result<ReadingRecord> ReadReading(const Statement& st, const std::string& path) {
  ReadingRecord r;
  r.id = st.Int64(0);
  r.session_id = st.Int64(1);
  r.step_index = st.Int(2);
  const std::string where = "reading " + std::to_string(r.id);
  BRDF_ASSIGN_OR_RETURN(r.kind, FromColumn(ParseReadingKind(st.Text(3)), path, where));
  r.pose = Pose{st.Double(4), st.Double(5), st.Double(6), st.Double(7)};
  r.directions = Directions{st.Double(8), st.Double(9), st.Double(10), st.Double(11)};
  const std::int64_t count = st.Int64(14);
  r.grid = WavelengthGrid{st.Double(12), st.Double(13), static_cast<std::size_t>(count)};
  BRDF_ASSIGN_OR_RETURN(r.spectrum, FromColumn(DecodeSpectrum(st.BlobView(15), r.grid.count), path,
                                               where + "'s spectrum"));
  r.quality_code = st.Int(16);
  r.flagged = st.Int(17) != 0;
  r.integration_ms = st.Int(18);
  r.attempts = st.Int(19);
  r.note = st.Text(20);
  r.reference_reading_id = st.OptionalInt64(21);
  r.dark_reading_id = st.OptionalInt64(22);
  r.meter_serial = st.Text(23);
  r.recorded_at = st.Double(24);
  if (st.IsNull(25)) return r;  // not estimated
  auto bytes = [&st](int column) {
    const Statement::Blob b = st.BlobView(column);
    return std::vector<std::uint8_t>(b.begin(), b.end());
  };
  const UncertaintyColumns columns{st.Text(25), bytes(26), bytes(27),  bytes(28),
                                   st.Text(29), bytes(30), st.Text(31)};
  BRDF_ASSIGN_OR_RETURN(r.uncertainty, FromColumn(DecodeUncertainty(columns, r.grid.count), path,
                                                  where + "'s uncertainty"));
  return r;
}

Result<ReadingPointRecord> ReadReadingPoint(const Statement& st, const std::string& path) {
  ReadingPointRecord r;
  r.id = st.Int64(0);
  BRDF_ASSIGN_OR_RETURN(
      r.kind, FromColumn(ParseReadingKind(st.Text(1)), path, "reading " + std::to_string(r.id)));
  r.pose = Pose{st.Double(2), st.Double(3), st.Double(4), st.Double(5)};
  r.directions = Directions{st.Double(6), st.Double(7), st.Double(8), st.Double(9)};
  r.flagged = st.Int(10) != 0;
  return r;
}

}  // namespace brdf::storage
