#include "storage/archive/writer.h"

#include <string_view>

#include "core/plan/plan_json.h"
#include "storage/round_picks.h"
#include "storage/spectrum_blob.h"
#include "storage/uncertainty_columns.h"

namespace brdf::storage {
namespace {

constexpr std::string_view kUpsertSession = R"sql(
INSERT INTO sessions (uuid, rig, rig_session_id, name, plan_kind, plan_json, state, state_reason,
  created_at, started_at, finished_at, created_by_role, total_steps, done_steps,
  white_reflectance, meter_serial, config_json, sample_id, sample_name, material,
  sample_description, tags, white_standard_id)
VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17, $18, $19, $20,
  $21, $22::text[], $23)
ON CONFLICT (uuid) DO UPDATE SET rig = EXCLUDED.rig, name = EXCLUDED.name,
  state = EXCLUDED.state, state_reason = EXCLUDED.state_reason,
  started_at = EXCLUDED.started_at, finished_at = EXCLUDED.finished_at,
  total_steps = EXCLUDED.total_steps, done_steps = EXCLUDED.done_steps,
  white_reflectance = EXCLUDED.white_reflectance, meter_serial = EXCLUDED.meter_serial,
  config_json = EXCLUDED.config_json, updated_at = now()
)sql";

constexpr std::string_view kUpsertStep = R"sql(
INSERT INTO steps (session_uuid, step_index, kind, alpha, beta, gamma, delta, prompt, prompt_kind,
  expected_action, target_theta_i, target_phi_i, target_theta_o, target_phi_o, label, state, note,
  completed_at)
VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17, $18)
ON CONFLICT (session_uuid, step_index) DO UPDATE SET state = EXCLUDED.state,
  note = EXCLUDED.note, completed_at = EXCLUDED.completed_at
)sql";

constexpr std::string_view kInsertReading = R"sql(
INSERT INTO readings (session_uuid, step_index, rig_reading_id, kind, alpha, beta, gamma, delta,
  theta_i, phi_i, theta_o, phi_o, wl_start_nm, wl_step_nm, wl_count, spectrum, quality_code,
  flagged, integration_ms, attempts, note, reference_reading_id, dark_reading_id, meter_serial,
  recorded_at)
VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17, $18, $19, $20,
  $21, $22, $23, $24, $25)
ON CONFLICT DO NOTHING
)sql";

constexpr std::string_view kInsertUncertainty = R"sql(
INSERT INTO reading_uncertainty (session_uuid, step_index, quantity, bands, value, combined,
  independent, components, contributions, not_estimated)
VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10)
ON CONFLICT DO NOTHING
)sql";

constexpr std::string_view kDeleteUncertainty = R"sql(
DELETE FROM reading_uncertainty WHERE session_uuid = $1 AND step_index = $2
)sql";

constexpr std::string_view kInsertDevice = R"sql(
INSERT INTO devices (rig, rig_device_id, session_uuid, kind, model, serial, first_seen)
VALUES ($1, $2, $3, $4, $5, $6, $7) ON CONFLICT DO NOTHING
)sql";

constexpr std::string_view kInsertAudit = R"sql(
INSERT INTO audit (rig, rig_audit_id, at, role, actor, action, session_uuid, detail)
VALUES ($1, $2, $3, $4, $5, $6, $7, $8) ON CONFLICT DO NOTHING
)sql";

// Events never change on the rig: a batch sent again rewrites the same values.
constexpr std::string_view kUpsertEvent = R"sql(
INSERT INTO session_events (session_uuid, rig_event_id, at, state, reason)
VALUES ($1, $2, $3, $4, $5)
ON CONFLICT (session_uuid, rig_event_id) DO UPDATE SET at = EXCLUDED.at, state = EXCLUDED.state,
  reason = EXCLUDED.reason
)sql";

// Rounds never change on the rig: a round shipped again is already there.
constexpr std::string_view kInsertRound = R"sql(
INSERT INTO adaptive_rounds (session_uuid, round, first_step, step_count, picks, predicted_gain,
  uncertainty_left, readings_used, created_at, spent_rig_s, spent_prompts, rig_s, prompts)
VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13)
ON CONFLICT (session_uuid, round) DO NOTHING
)sql";

// A PostgreSQL array literal of text values: {"a","b \"c\""}.
std::string TextArray(const google::protobuf::RepeatedPtrField<std::string>& values) {
  std::string out = "{";
  for (int i = 0; i < values.size(); ++i) {
    if (i > 0) out += ',';
    out += '"';
    for (char c : values[i]) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
    out += '"';
  }
  return out + "}";
}

std::optional<std::string> UuidOf(const ShipBatch& batch, std::optional<std::int64_t> session) {
  if (!session.has_value()) return std::nullopt;
  auto it = batch.uuids.find(*session);
  if (it == batch.uuids.end()) return std::nullopt;
  return it->second;
}

Status WriteSession(PgConnection& conn, const std::string& rig, const SessionRecord& s) {
  v1::Sample sample;
  if (Result<v1::Plan> plan = plan::ParsePlanJson(s.plan_json); plan.ok()) {
    sample = plan->sample();
  }
  PgParams p;
  p.Add(s.uuid)
      .Add(s.rig.empty() ? rig : s.rig)
      .Add(s.id)
      .Add(s.name)
      .Add(s.plan_kind)
      .Add(s.plan_json)
      .Add(std::string(ToString(s.state)))
      .Add(s.state_reason)
      .Add(s.created_at)
      .Add(s.started_at)
      .Add(s.finished_at)
      .Add(s.created_by_role)
      .Add(s.total_steps)
      .Add(s.done_steps)
      .Add(s.white_reflectance)
      .Add(s.meter_serial)
      .Add(s.config_json)
      .Add(sample.id())
      .Add(sample.name())
      .Add(sample.material())
      .Add(sample.description())
      .Add(TextArray(sample.tags()))
      .Add(sample.white_standard_id());
  return conn.QueryPrepared("upsert_session", kUpsertSession, std::move(p))
      .status()
      .WithContext("archiving session " + s.uuid);
}

Status WriteStep(PgConnection& conn, const std::string& uuid, const StepRecord& s) {
  const std::optional<Directions>& t = s.target;
  PgParams p;
  p.Add(uuid)
      .Add(s.step_index)
      .Add(std::string(ToString(s.kind)))
      .Add(s.pose.alpha)
      .Add(s.pose.beta)
      .Add(s.pose.gamma)
      .Add(s.pose.delta)
      .Add(s.prompt)
      .Add(s.prompt_kind)
      .Add(s.expected_action)
      .Add(t ? std::optional<double>(t->theta_i) : std::nullopt)
      .Add(t ? std::optional<double>(t->phi_i) : std::nullopt)
      .Add(t ? std::optional<double>(t->theta_o) : std::nullopt)
      .Add(t ? std::optional<double>(t->phi_o) : std::nullopt)
      .Add(s.label)
      .Add(std::string(ToString(s.state)))
      .Add(s.note)
      .Add(s.completed_at);
  return conn.QueryPrepared("upsert_step", kUpsertStep, std::move(p))
      .status()
      .WithContext("archiving step " + std::to_string(s.step_index) + " of session " + uuid);
}

// The reading's uncertainty budget, when it has one (none: not estimated, no row).
Status WriteUncertainty(PgConnection& conn, const std::string& uuid, const ReadingRecord& r,
                        const std::string& what) {
  if (!r.uncertainty.has_value()) return Status::Ok();
  Result<UncertaintyColumns> u = EncodeUncertainty(*r.uncertainty, r.grid.count);
  if (!u.ok()) return u.status().WithContext(what);
  PgParams p;
  p.Add(uuid)
      .Add(r.step_index)
      .Add(u->quantity)
      .Add(static_cast<std::int64_t>(r.grid.count))
      .AddBytes(u->value)
      .AddBytes(u->combined)
      .AddBytes(u->independent)
      .Add(u->components)
      .AddBytes(u->contributions)
      .Add(u->not_estimated);
  return conn.QueryPrepared("insert_uncertainty", kInsertUncertainty, std::move(p))
      .status()
      .WithContext(what + ": its uncertainty");
}

// A reading's budget as the rig has it now, in place of the one it was shipped with.
Status ReplaceUncertainty(PgConnection& conn, const std::string& uuid, const ReadingRecord& r) {
  const std::string what = "replacing the uncertainty of reading " + std::to_string(r.id) +
                           " (step " + std::to_string(r.step_index) + ") of session " + uuid;
  PgParams p;
  p.Add(uuid).Add(r.step_index);
  BRDF_RETURN_IF_ERROR(conn.QueryPrepared("delete_uncertainty", kDeleteUncertainty, std::move(p))
                           .status()
                           .WithContext(what));
  return WriteUncertainty(conn, uuid, r, what);
}

Status WriteRound(PgConnection& conn, const std::string& uuid, const ArchivedRound& a) {
  const RoundRecord& r = a.record;
  PgParams p;
  p.Add(uuid)
      .Add(r.round)
      .Add(r.first_step)
      .Add(r.step_count)
      .Add(EncodePicks(r.picks))
      .Add(r.predicted_gain)
      .Add(r.uncertainty_left)
      .Add(r.readings_used)
      .Add(r.created_at)
      .Add(a.spent_rig_s)
      .Add(a.spent_prompts)
      .Add(a.rig_s)
      .Add(a.prompts);
  return conn.QueryPrepared("insert_round", kInsertRound, std::move(p))
      .status()
      .WithContext("archiving round " + std::to_string(r.round) + " of session " + uuid);
}

Status WriteReading(PgConnection& conn, const std::string& uuid, const ReadingRecord& r) {
  PgParams p;
  p.Add(uuid)
      .Add(r.step_index)
      .Add(r.id)
      .Add(std::string(ToString(r.kind)))
      .Add(r.pose.alpha)
      .Add(r.pose.beta)
      .Add(r.pose.gamma)
      .Add(r.pose.delta)
      .Add(r.directions.theta_i)
      .Add(r.directions.phi_i)
      .Add(r.directions.theta_o)
      .Add(r.directions.phi_o)
      .Add(r.grid.start_nm)
      .Add(r.grid.step_nm)
      .Add(static_cast<std::int64_t>(r.grid.count))
      .AddBytes(EncodeSpectrum(r.spectrum))
      .Add(r.quality_code)
      .Add(r.flagged)
      .Add(r.integration_ms)
      .Add(r.attempts)
      .Add(r.note)
      .Add(r.reference_reading_id)
      .Add(r.dark_reading_id)
      .Add(r.meter_serial)
      .Add(r.recorded_at);
  const std::string what = "archiving reading " + std::to_string(r.id) + " of session " + uuid;
  BRDF_RETURN_IF_ERROR(conn.QueryPrepared("insert_reading", kInsertReading, std::move(p))
                           .status()
                           .WithContext(what));
  return WriteUncertainty(conn, uuid, r, what);
}

}  // namespace

Status WriteToArchive(PgConnection& conn, const std::string& rig, const ShipBatch& batch) {
  BRDF_ASSIGN_OR_RETURN(PgTransaction tx, PgTransaction::Begin(conn));
  for (const SessionRecord& s : batch.sessions) BRDF_RETURN_IF_ERROR(WriteSession(conn, rig, s));
  for (const StepRecord& s : batch.steps) {
    std::optional<std::string> uuid = UuidOf(batch, s.session_id);
    if (!uuid) return Internal("step of session " + std::to_string(s.session_id) + " has no uuid");
    BRDF_RETURN_IF_ERROR(WriteStep(conn, *uuid, s));
  }
  for (const ArchivedRound& r : batch.rounds) {
    std::optional<std::string> uuid = UuidOf(batch, r.record.session_id);
    if (!uuid) {
      return Internal("round " + std::to_string(r.record.round) + " of session " +
                      std::to_string(r.record.session_id) + " has no uuid");
    }
    BRDF_RETURN_IF_ERROR(WriteRound(conn, *uuid, r));
  }
  for (const ReadingRecord& r : batch.readings) {
    std::optional<std::string> uuid = UuidOf(batch, r.session_id);
    if (!uuid) return Internal("reading " + std::to_string(r.id) + "'s session has no uuid");
    BRDF_RETURN_IF_ERROR(WriteReading(conn, *uuid, r));
  }
  for (const ReadingRecord& r : batch.rebudgeted) {
    std::optional<std::string> uuid = UuidOf(batch, r.session_id);
    if (!uuid) return Internal("reading " + std::to_string(r.id) + "'s session has no uuid");
    BRDF_RETURN_IF_ERROR(ReplaceUncertainty(conn, *uuid, r));
  }
  for (const DeviceRecord& d : batch.devices) {
    PgParams p;
    p.Add(rig).Add(d.id).Add(UuidOf(batch, d.session_id)).Add(d.kind).Add(d.model).Add(d.serial);
    p.Add(d.first_seen);
    BRDF_RETURN_IF_ERROR(conn.QueryPrepared("insert_device", kInsertDevice, std::move(p)).status());
  }
  for (const AuditRecord& a : batch.audit) {
    PgParams p;
    p.Add(rig).Add(a.id).Add(a.at).Add(a.role).Add(a.actor).Add(a.action);
    p.Add(UuidOf(batch, a.session_id)).Add(a.detail);
    BRDF_RETURN_IF_ERROR(conn.QueryPrepared("insert_audit", kInsertAudit, std::move(p)).status());
  }
  for (const SessionEventRecord& e : batch.events) {
    std::optional<std::string> uuid = UuidOf(batch, e.session_id);
    if (!uuid) return Internal("event " + std::to_string(e.id) + "'s session has no uuid");
    PgParams p;
    p.Add(*uuid).Add(e.id).Add(e.at).Add(std::string(ToString(e.state))).Add(e.reason);
    BRDF_RETURN_IF_ERROR(
        conn.QueryPrepared("upsert_event", kUpsertEvent, std::move(p))
            .status()
            .WithContext("archiving event " + std::to_string(e.id) + " of session " + *uuid));
  }
  return tx.Commit();
}

}  // namespace brdf::storage
