// The device side of one reading step (reference, dark or sample), as small handlers the executor
// calls in turn (DESIGN.md, "The executor's rules"):
//
//   MeasureReading      the stage to the step's pose when it is not known to be there, the meter
//                       configured, MeasureSpectrum — each attempt run by the caller's retry
//                       policy; starts the pipelined move once the meter holds the measurement.
//   PipelinedMove       that move, on a thread of its own, and where it left the stage.
//   BuildReadingRecord  the reading as storage keeps it (pose, directions, spectrum, quality,
//                       the reference and dark a sample is divided by, the meter's serial).
//   RecordMeterOnce     the meter's identity with the session, once per run.
//
// The commit (the reading and its done mark in one transaction) and the move's done mark stay
// with the executor, which owns the session's progress and its host. None of these handlers
// decides a session state; none throws.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <thread>

#include "core/call_context.h"
#include "core/geometry.h"
#include "core/plan/plan_settings.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"
#include "core/status.h"
#include "daemon/engine/rig.h"
#include "drivers/spectroradiometer.h"
#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::daemon {

// Where the stage is known to be: the commanded pose of the last move that finished in this run
// (nullopt at the start of a run, after a failed or cancelled move, and while a pipelined move
// runs), and the stage's feedback after that move.
struct StageKnowledge {
  std::optional<Pose> target;
  Pose feedback;

  bool At(const Pose& pose) const { return target.has_value() && *target == pose; }
};

// What the executor knows of the meter within one run.
struct MeterKnowledge {
  bool configured = false;  // Configure succeeded in this run
  bool dark = false;        // the dark flag it was last configured with
  bool recorded = false;    // RecordMeterOnce has run
  int last_quality = -1;    // the last quality code the meter reported (-1: none yet)
};

// Whether `failure` (a step's error after the retry policy) is the meter's overload: the light
// too bright even at the shortest integration the quality policy may use. Keyed by the meter's
// model, since the device code is the meter's own: a PR-650's quality 19; a CS-2000's ER10, which
// the policy handles as 19 (drivers/cs2000/protocol.h); a PR-655/670 code the policy handles as
// 19 (drivers/pr670/protocol.h; none of the codes it knows today). False for any other error or
// an unknown meter.
bool MeterOverloaded(const std::optional<drivers::MeterIdentity>& meter, const Status& failure);

// Moves the motorized axes of the rig's stage to `pose` (α, β; γ and δ where the stage has them)
// and reads the pose back. Returns the feedback on the moved axes, the commanded value where the
// feedback cannot be read, or the move's error.
Result<Pose> MoveStageTo(Rig& rig, const Pose& pose, const CallContext& ctx);

// Clears the alarms of the axes that report one (before retrying a failed move), logging each
// for `session`. Errors are left to the retried move to report.
void ResetStageAlarms(Rig& rig, std::int64_t session, const CallContext& ctx);

// A move started on a second thread while the meter transfers a spectrum (pipelining). Waits
// for the thread on destruction.
class PipelinedMove {
 public:
  PipelinedMove() = default;
  ~PipelinedMove() { Join(); }
  PipelinedMove(const PipelinedMove&) = delete;
  PipelinedMove& operator=(const PipelinedMove&) = delete;

  // Starts moving the rig's stage to `target` (the pose of step `step_index`) within `ctx`;
  // the stage's position is unknown (stage.target reset) until Settle.
  void Start(Rig& rig, int step_index, const Pose& target, const CallContext& ctx,
             StageKnowledge& stage);
  bool started() const { return step_index_ >= 0; }
  int step_index() const { return step_index_; }

  // Waits for the move and records where it left the stage: at its target, with the feedback,
  // when it succeeded; unknown otherwise. Nothing when not started. Idempotent.
  void Settle(StageKnowledge& stage);
  // After Settle: Ok when the move succeeded, else its error (kInternal when it left none).
  Status status() const;

  // Settles the move and forgets it (the attempt it belonged to failed: the stage is moved back
  // before measuring again).
  void Abandon(StageKnowledge& stage);

 private:
  void Join();

  int step_index_ = -1;
  Pose target_;
  std::thread thread_;
  std::optional<Result<Pose>> result_;  // written by thread_, read after Join
};

// What measuring one reading step needs.
struct ReadingRequest {
  int step_index = 0;
  std::string step_name;  // "step 4 (white)", for error contexts
  Pose pose;              // the step's pose
  // Where the stage must be (the pose of the last move before the step); nullopt on plans
  // without moves (sample-fixed: the holder stays where it is).
  std::optional<Pose> required;
  drivers::MeasurementSettings settings;
  // The move started once the meter holds the measurement (pipelining): its step and pose.
  std::optional<int> pipelined_step;
  Pose pipelined_pose;
};

// The request's settings for the meter: the plan's integration time and averages (at least 1);
// the dark flag on dark steps (the driver then accepts its low-light codes).
drivers::MeasurementSettings MeterSettingsFor(const plan::MeasurementChoice& measurement,
                                              storage::StepKind kind);

// What the meter gave for one reading step.
struct TakenReading {
  drivers::MeasurementOutcome outcome;
  drivers::SpectrumReport report;
  // The step's pose with the motorized axes (α, β; γ and δ where the rig has them) where the
  // stage reported them; the step's pose as stored when no move precedes the step.
  Pose pose;
  int measurements = 0;  // measurements taken over every attempt (the meter's own retries too)
};

// Runs one attempt per call of the function it is given, per the caller's retry policy (see
// RunWithRetry); returns what the last attempt returned.
using RetryRunner = std::function<Status(const std::function<Status(std::uint32_t attempt)>&)>;

// What the device handlers work with: the rig, the session (for the log) and a fresh device
// call context per attempt.
struct ReadingDevices {
  Rig& rig;
  std::int64_t session = 0;
  std::function<CallContext()> call_context;
};

// Measures the request's step, each attempt through `retry`:
//  - abandons the previous attempt's pipelined move, if any;
//  - when `required` is set and `stage` is not known to be there, moves the stage there
//    (resetting alarms first on a later attempt), and takes the stage's feedback as the pose;
//  - configures the meter when it is not configured yet, on a later attempt, or when the dark
//    flag changes (`meter` records it);
//  - MeasureSpectrum; once the meter holds the measurement, records its quality code, counts its
//    measurements and, when `pipelined_step` is set, starts `move` to `pipelined_pose`.
// A failed attempt's error names what failed ("moving to the pose of …", "configuring the meter",
// "measuring the spectrum of …"); a meter's device error leaves its quality code in `meter`.
// `move` may be running when this returns (success or error): the caller settles it.
Result<TakenReading> MeasureReading(const ReadingDevices& devices, const plan::RigDescription& rig,
                                    const ReadingRequest& request, const RetryRunner& retry,
                                    StageKnowledge& stage, MeterKnowledge& meter,
                                    PipelinedMove& move);

// Besides what the meter gave, what a reading's record is made of.
struct RecordSources {
  bool sample_fixed = false;  // lamp and detector placed by hand at the step's target
  HolderConvention convention;
  std::optional<std::int64_t> reference;  // the session's latest reference reading
  std::optional<std::int64_t> dark;       // the session's latest dark reading
  std::optional<drivers::MeterIdentity> meter;
};

// The record of `step`'s reading, ready to store (id, session and step filled by the store): its
// kind from the step; the reached pose; directions from the pose (sample-fixed with a target:
// the target); spectrum, grid, quality, flag, integration and note from the meter; attempts at
// least 1; on samples only, the reference and dark they are divided by; the meter's serial.
storage::ReadingRecord BuildReadingRecord(const storage::StepRecord& step, TakenReading taken,
                                          const RecordSources& sources);

// The first time in a run (`meter.recorded` unset): stores the meter's serial with the session
// when `session` names another, and records the device for the session. Storage errors are
// ignored (the reading carries the serial all the same).
void RecordMeterOnce(storage::SessionStore& store, const storage::SessionRecord& session,
                     const drivers::MeterIdentity& identity, MeterKnowledge& meter);

}  // namespace brdf::daemon
