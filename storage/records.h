// What storage keeps, as plain C++ values: sessions, their planned steps, the readings taken at
// those steps, the devices seen and the audit trail. These mirror the tables in schema.md one to
// one; the enums are stored as the lower-case words their ToString returns.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "core/readings/reading.h"
#include "core/session_state.h"
#include "core/status.h"
#include "core/uncertainty/budget.h"
#include "core/wavelength_grid.h"

namespace brdf::storage {

// Session states are core's (core/session_state.h: SessionState, SessionStateName,
// ParseSessionState, IsTerminal, and the transition table the daemon follows). Storage only
// refuses to leave a terminal state and to mark a session completed while steps are pending.

// What a step does. Only reference, dark and sample steps produce a reading.
enum class StepKind { kMove, kPrompt, kReference, kDark, kSample };

// pending until done (its reading, if any, stored) or skipped (with a note saying why).
enum class StepState { kPending, kDone, kSkipped };

// The reading a measuring step produced: I(λ) of the sample, I0(λ) of the white standard, or the
// dark (ambient) D(λ). core/readings' ReadingKind, stored as its word (ToString below).
using ::brdf::ReadingKind;

std::string_view ToString(SessionState state);  // SessionStateName
std::string_view ToString(StepKind kind);
std::string_view ToString(StepState state);
std::string_view ToString(ReadingKind kind);
// kInvalidArgument naming the accepted words when `text` is not one of them. (Session states:
// brdf::ParseSessionState.)
Result<StepKind> ParseStepKind(std::string_view text);
Result<StepState> ParseStepState(std::string_view text);
Result<ReadingKind> ParseReadingKind(std::string_view text);

// running, pausing and awaiting_operator: a daemon was driving the session.
bool IsActive(SessionState state);
// The reading a step of this kind produces; nullopt for move and prompt.
std::optional<ReadingKind> ReadingKindFor(StepKind kind);

// Seconds since the Unix epoch (UTC), fractional. All timestamps in storage use it.
using UnixSeconds = double;

// What the daemon knows when a session is submitted.
struct NewSession {
  std::string name;
  std::string plan_kind;        // "sample_rotation", "sample_fixed", … (the plan's own word)
  std::string plan_json;        // the plan as submitted, verbatim
  std::string created_by_role;  // the submitter's role ("operator", "admin")
  std::optional<double> white_reflectance;  // ρw of the white standard (the paper's 0.99)
  std::string meter_serial;        // the spectroradiometer expected/used; may be filled later
  std::string config_json = "{}";  // anything else worth keeping (rig config, settings)
  std::string uuid;  // global identity (lower-case v4 UUID); empty: the store makes one
  std::string rig;   // the rig recording it ([rig] name)
};

struct SessionRecord {
  std::int64_t id = 0;
  std::string name;
  std::string plan_kind;
  std::string plan_json;
  SessionState state = SessionState::kQueued;
  std::string state_reason;  // why it is in that state ("operator paused", an error message)
  UnixSeconds created_at = 0;
  std::optional<UnixSeconds> started_at;   // first time it became running
  std::optional<UnixSeconds> finished_at;  // when it became completed, aborted or failed
  std::string created_by_role;
  int total_steps = 0;
  int done_steps = 0;  // steps finished: done or skipped
  std::optional<double> white_reflectance;
  std::string meter_serial;
  std::string config_json;
  std::string uuid;  // global identity: a random (version 4) UUID, lower-case with hyphens
  std::string rig;   // the rig that recorded it; '' for sessions older than rig naming
  // The session's wavelength grid: its first reading's (CompleteStepWithReading refuses a reading
  // on another); nullopt before the first reading.
  std::optional<WavelengthGrid> grid;
};

// One planned step. Steps are numbered 0, 1, 2, … in execution order.
struct StepRecord {
  std::int64_t session_id = 0;  // filled by the store
  int step_index = 0;
  StepKind kind = StepKind::kSample;
  Pose pose;                                   // where the rig goes for this step (degrees)
  std::optional<std::string> prompt;           // prompt steps: the instruction to the operator
  std::optional<std::string> prompt_kind;      // prompt steps: the plan's word for the action
                                               // ("relocate_detector", "mount_white", …)
  std::optional<std::string> expected_action;  // prompt steps: what the confirmation asserts
  std::optional<Directions> target;            // reading steps: θi φi θo φo planned (degrees)
  std::string label;  // short human name ("sample δ 22.5° α 10° β -35° γ 0°")
  StepState state = StepState::kPending;    // filled by the store
  std::optional<std::string> note;          // why it was skipped
  std::optional<UnixSeconds> completed_at;  // when it became done or skipped
};

// What a session's steps add up to, for its progress: sample readings planned and finished (done
// or skipped), and the index of the first pending step (-1 when none is pending).
struct StepTally {
  std::uint32_t samples = 0;
  std::uint32_t done_samples = 0;
  int first_pending = -1;
};
StepTally TallySteps(std::span<const StepRecord> steps);

// One measured spectrum and everything needed to use it again: where the rig was, what the meter
// said, and which reference (and dark) reading it is to be divided by.
struct ReadingRecord {
  std::int64_t id = 0;          // filled by the store
  std::int64_t session_id = 0;  // filled by the store
  int step_index = 0;           // filled by the store
  ReadingKind kind = ReadingKind::kSample;
  Pose pose;              // the pose actually reached
  Directions directions;  // θi φi θo φo in the sample frame (degrees)
  WavelengthGrid grid;
  std::vector<double> spectrum;  // grid.count values (radiance as the meter reported it)
  int quality_code = 0;          // the meter's quality code (0 = OK)
  bool flagged = false;          // usable but flagged by the quality policy
  int integration_ms = 0;        // 0 = adaptive
  int attempts = 1;              // measurements taken, including retries
  std::string note;              // what the quality policy did ("halved to 250 ms")
  std::optional<std::int64_t> reference_reading_id;  // the I0 this sample is divided by
  std::optional<std::int64_t> dark_reading_id;       // the D subtracted, when measured
  std::string meter_serial;
  UnixSeconds recorded_at = 0;  // 0: the store uses its clock
  // The budget of the reading's BRDF or reflectance per band (docs/uncertainty.md), stored with
  // the reading (schema v5). nullopt: not estimated -- every reading stored before v5, darks and
  // references. Read back without its `value` (derived again from the raw readings).
  std::optional<uncertainty::ReadingBudget> uncertainty;
};

// Where a reading was taken, without its spectrum: what a plot of a session's readings needs
// (SessionReader::GetReadingPoints; Figure 7).
struct ReadingPointRecord {
  std::int64_t id = 0;
  ReadingKind kind = ReadingKind::kSample;
  Pose pose;
  Directions directions;
  bool flagged = false;
};

// A device seen by the daemon; recorded once per (session, kind, model, serial).
struct DeviceRecord {
  std::int64_t id = 0;
  std::optional<std::int64_t> session_id;  // nullopt: seen at daemon level, not for a session
  std::string kind;                        // "spectroradiometer", "rotation_stage"
  std::string model;
  std::string serial;
  UnixSeconds first_seen = 0;  // 0: the store uses its clock
};

// Who did what. `actor` is a token's NAME ("lab-pc-2"), never the token itself.
struct AuditRecord {
  std::int64_t id = 0;
  UnixSeconds at = 0;  // 0: the store uses its clock
  std::string role;
  std::string actor;
  std::string action;  // "session.create", "session.pause", …
  std::optional<std::int64_t> session_id;
  std::string detail;
};

// One entry of a session's history (schema v4's session_events): the session entered `state`, or
// its reason changed, at `at`. Written by the database's triggers, never by hand.
struct SessionEventRecord {
  std::int64_t id = 0;
  std::int64_t session_id = 0;
  UnixSeconds at = 0;
  SessionState state = SessionState::kQueued;
  std::string reason;
};

// One round of an adaptive session (schema v6's adaptive_rounds; docs/adaptive.md): the poses the
// engine chose, stored with the round's steps in one transaction before any of them is measured.
struct RoundPick {
  Pose pose;                  // model angles (α, β, γ, δ), as the chooser gave them
  double predicted_gain = 0;  // the fall of the integrated uncertainty it was predicted to bring
};
struct RoundRecord {
  std::int64_t session_id = 0;
  int round = 0;                 // 1, 2, 3, … (the seed is round 0 and has no record)
  int first_step = 0;            // the index of the round's first step
  int step_count = 0;            // its steps: first_step … first_step + step_count − 1
  std::vector<RoundPick> picks;  // in measurement order
  double predicted_gain = 0;     // sum of the picks' gains
  double uncertainty_left = 0;   // the integrated uncertainty before the round (the target's unit)
  int readings_used = 0;         // sample readings it was chosen from
  UnixSeconds created_at = 0;    // filled by the store
};

}  // namespace brdf::storage
