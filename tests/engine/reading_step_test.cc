// The reading step's handlers one by one (daemon/engine/retry.h, daemon/engine/reading_step.h),
// and the executor's commit of a reading, against an in-process scripted meter and stage behind
// the driver interfaces (drivers/spectroradiometer.h, drivers/rotation_stage.h): no brdf-sim.
#include "daemon/engine/reading_step.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "daemon/engine/executor.h"
#include "daemon/engine/retry.h"
#include "daemon/sessions/session_plan.h"
#include "storage/session_store.h"
#include "tests/support/test_env.h"

namespace brdf::daemon {
namespace {

using namespace std::chrono_literals;

// A meter whose measurements and transfers follow a script (Ok by default). Configure calls are
// recorded; a transfer may wait until the scripted stage has started a given number of moves
// (to see a pipelined move overlap the transfer).
class ScriptedMeter : public drivers::Spectroradiometer {
 public:
  Status Connect(const CallContext&) override {
    connected_ = true;
    return Status::Ok();
  }
  void Disconnect() override { connected_ = false; }
  bool connected() const override { return connected_; }
  Result<drivers::MeterIdentity> Identify(const CallContext&) override {
    return drivers::MeterIdentity{"SCRIPTED-650", "SN-42", WavelengthGrid{380, 4, 3}};
  }
  Status Configure(const drivers::MeasurementSettings& settings, const CallContext&) override {
    configured.push_back(settings);
    return Status::Ok();
  }
  Result<drivers::MeasurementOutcome> Measure(const CallContext&) override {
    if (!measure_results.empty()) {
      Result<drivers::MeasurementOutcome> r = measure_results.front();
      measure_results.pop_front();
      return r;
    }
    drivers::MeasurementOutcome o;
    o.quality_code = 0;
    o.integration_ms = 250;
    o.attempts = 1;
    o.note = "as planned";
    return o;
  }
  Result<drivers::SpectrumReport> TransferSpectrum(const CallContext&) override;

  std::vector<drivers::MeasurementSettings> configured;
  std::deque<Result<drivers::MeasurementOutcome>> measure_results;
  std::deque<Status> transfer_errors;  // Ok entries transfer normally
  std::function<void()> during_transfer;

 private:
  bool connected_ = false;
};

Result<drivers::SpectrumReport> ScriptedMeter::TransferSpectrum(const CallContext&) {
  if (during_transfer) during_transfer();
  if (!transfer_errors.empty()) {
    Status st = transfer_errors.front();
    transfer_errors.pop_front();
    if (!st.ok()) return st;
  }
  drivers::SpectrumReport r;
  r.grid = WavelengthGrid{380, 4, 3};
  r.radiance = {1.0, 2.0, 3.0};
  return r;
}

// A stage that reaches every target at once and reads back the target plus `feedback_offset`
// on α (so a test can tell the feedback from the command). Moves may fail per a script.
class ScriptedStage : public drivers::RotationStage {
 public:
  explicit ScriptedStage(bool gamma_axis, bool detector_arm)
      : gamma_axis_(gamma_axis), detector_arm_(detector_arm) {}

  Status Connect(const CallContext&) override {
    connected_ = true;
    return Status::Ok();
  }
  void Disconnect() override { connected_ = false; }
  bool connected() const override { return connected_; }
  bool HasAxis(drivers::Axis axis) const override {
    if (axis == drivers::Axis::kGamma) return gamma_axis_;
    if (axis == drivers::Axis::kDelta) return detector_arm_;
    return true;
  }
  Status MoveTo(const drivers::StageTarget& target, const CallContext&) override {
    std::lock_guard lock(mu_);
    moves_.push_back(target);
    cv_.notify_all();
    if (!move_errors.empty()) {
      Status st = move_errors.front();
      move_errors.pop_front();
      if (!st.ok()) return st;
    }
    if (target.alpha) pose_.alpha = *target.alpha;
    if (target.beta) pose_.beta = *target.beta;
    if (target.gamma) pose_.gamma = *target.gamma;
    if (target.delta) pose_.delta = *target.delta;
    return Status::Ok();
  }
  Result<drivers::AxisState> ReadAxis(drivers::Axis axis, const CallContext&) override {
    std::lock_guard lock(mu_);
    drivers::AxisState s;
    s.alarm = axis == drivers::Axis::kAlpha && alpha_alarm_;
    s.alarm_code = s.alarm ? 7 : 0;
    return s;
  }
  Result<Pose> ReadPose(const CallContext&) override {
    std::lock_guard lock(mu_);
    Pose p = pose_;
    p.alpha += feedback_offset;
    return p;
  }
  Status ResetAlarm(drivers::Axis, const CallContext&) override {
    std::lock_guard lock(mu_);
    ++alarm_resets_;
    alpha_alarm_ = false;
    return Status::Ok();
  }
  Status Home(drivers::Axis, const CallContext&) override { return Status::Ok(); }
  Status Stop(const CallContext&) override { return Status::Ok(); }

  std::vector<drivers::StageTarget> moves() const {
    std::lock_guard lock(mu_);
    return moves_;
  }
  // Waits until `n` moves were asked for; false after `timeout`.
  bool WaitForMoves(std::size_t n, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return moves_.size() >= n; });
  }
  void RaiseAlphaAlarm() {
    std::lock_guard lock(mu_);
    alpha_alarm_ = true;
  }
  int alarm_resets() const {
    std::lock_guard lock(mu_);
    return alarm_resets_;
  }

  double feedback_offset = 0.01;
  std::deque<Status> move_errors;  // set before the stage is used

 private:
  const bool gamma_axis_;
  const bool detector_arm_;
  bool connected_ = false;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::vector<drivers::StageTarget> moves_;
  Pose pose_;
  bool alpha_alarm_ = false;
  int alarm_resets_ = 0;
};

Pose At(double alpha, double beta, double gamma = 0, double delta = 0) {
  Pose p;
  p.alpha = alpha;
  p.beta = beta;
  p.gamma = gamma;
  p.delta = delta;
  return p;
}

// Attempts 1 … n, stopping at the first success (no backoff, no faults).
RetryRunner Attempts(std::uint32_t n) {
  return [n](const std::function<Status(std::uint32_t)>& attempt) {
    Status last = Internal("no attempt");
    for (std::uint32_t a = 1; a <= n; ++a) {
      last = attempt(a);
      if (last.ok()) break;
    }
    return last;
  };
}

// A rig of a scripted meter and stage (α/β and a detector arm, γ a dial).
struct ScriptedRig {
  ScriptedRig() {
    auto m = std::make_unique<ScriptedMeter>();
    auto s = std::make_unique<ScriptedStage>(/*gamma_axis=*/false, /*detector_arm=*/true);
    meter = m.get();
    stage = s.get();
    description.has_gamma_axis = false;
    description.has_detector_arm = true;
    rig = std::make_unique<Rig>(std::move(m), Rig::DeviceInfo{"SCRIPTED-650", "script"},
                                std::move(s), Rig::DeviceInfo{"scripted stage", "script"},
                                description, Rig::Options());
  }
  ReadingDevices devices() {
    return ReadingDevices{*rig, 7, [] { return CallContext::WithTimeout(5s); }};
  }
  // MeasureReading on this rig, with what the executor knows kept here between calls.
  Result<TakenReading> Measure(const ReadingRequest& request, const RetryRunner& retry) {
    return MeasureReading(devices(), description, request, retry, known_stage, known_meter, move);
  }
  Result<TakenReading> Measure(const ReadingRequest& request) {
    return Measure(request, Attempts(1));
  }

  ScriptedMeter* meter = nullptr;
  ScriptedStage* stage = nullptr;
  plan::RigDescription description;
  std::unique_ptr<Rig> rig;
  StageKnowledge known_stage;
  MeterKnowledge known_meter;
  PipelinedMove move;  // after rig: its thread uses the rig
};

ReadingRequest SampleRequest(int index, const Pose& pose) {
  ReadingRequest r;
  r.step_index = index;
  r.step_name = "step " + std::to_string(index);
  r.pose = pose;
  r.required = pose;
  r.settings.integration_ms = 250;
  return r;
}

// Step 3 at α 10°, the move of step 4 to α 20° β 5° pipelined behind it.
ReadingRequest PipelinedRequest() {
  ReadingRequest r = SampleRequest(3, At(10, 0));
  r.pipelined_step = 4;
  r.pipelined_pose = At(20, 5);
  return r;
}

// --- RunWithRetry / FaultFor -----------------------------------------------------------------

struct Failure {
  StatusCode code;
  std::uint32_t attempt;
  bool will_retry;
};

class RetryTest : public ::testing::Test {
 protected:
  RetryTest() { retry.backoff_ms = 0; }
  Status Run(std::uint32_t first, std::vector<Status> script) {
    std::size_t next = 0;
    return RunWithRetry(
        retry, first, Clock::Real(), cancel,
        [&](std::uint32_t attempt) {
          attempts.push_back(attempt);
          return next < script.size() ? script[next++] : Status::Ok();
        },
        [&](const Status& st, std::uint32_t attempt, std::uint32_t, bool will_retry) {
          failures.push_back({st.code(), attempt, will_retry});
        });
  }
  plan::RetrySettings retry;
  CancelToken cancel;
  std::vector<std::uint32_t> attempts;
  std::vector<Failure> failures;
};

TEST_F(RetryTest, RetriesWhatALaterAttemptMayCureUntilItSucceeds) {
  const Status st = Run(1, {Timeout("slow"), DeviceError(7, "alarm")});
  EXPECT_TRUE(st.ok()) << st.ToString();
  EXPECT_EQ(attempts, (std::vector<std::uint32_t>{1, 2, 3}));
  ASSERT_EQ(failures.size(), 2u);
  EXPECT_EQ(failures[0].code, StatusCode::kTimeout);
  EXPECT_TRUE(failures[0].will_retry);
  EXPECT_EQ(failures[1].attempt, 2u);
  EXPECT_TRUE(failures[1].will_retry);
}

TEST_F(RetryTest, GivesUpAfterTheLastAttemptWithItsError) {
  const Status st = Run(1, {Timeout("1"), Timeout("2"), Timeout("3")});
  EXPECT_EQ(st.code(), StatusCode::kTimeout);
  EXPECT_EQ(st.message(), "3");
  ASSERT_EQ(failures.size(), 3u);
  EXPECT_FALSE(failures[2].will_retry);
}

TEST_F(RetryTest, DoesNotRetryWhatNoAttemptCanCure) {
  const Status st = Run(1, {InvalidArgument("beyond travel")});
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(attempts.size(), 1u);
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_FALSE(failures[0].will_retry);
}

TEST_F(RetryTest, StartsAtTheGivenAttempt) {
  const Status st = Run(2, {Timeout("a"), Timeout("b")});
  EXPECT_EQ(st.code(), StatusCode::kTimeout);
  EXPECT_EQ(attempts, (std::vector<std::uint32_t>{2, 3}));
}

TEST_F(RetryTest, ACancelledRunMakesNoAttemptAndReportsNothing) {
  cancel.Cancel("abort");
  const Status st = Run(1, {});
  EXPECT_EQ(st.code(), StatusCode::kCancelled);
  EXPECT_TRUE(attempts.empty());
  EXPECT_TRUE(failures.empty());
}

TEST_F(RetryTest, AnAttemptCancelledUnderwayIsNotReportedAsAFault) {
  const Status st = Run(1, {Cancelled("pause immediate")});
  EXPECT_EQ(st.code(), StatusCode::kCancelled);
  EXPECT_TRUE(failures.empty());
}

TEST(FaultFor, CarriesTheStatusAndTheAttempt) {
  const v1::Fault f = FaultFor(4, DeviceError(18, "quality 18"), 2, true, 18);
  EXPECT_EQ(f.step_index(), 4);
  EXPECT_EQ(f.code(), StatusCodeName(StatusCode::kDeviceError));
  EXPECT_EQ(f.reason(), "quality 18");
  EXPECT_EQ(f.device_code(), 18);
  EXPECT_EQ(f.attempt(), 2u);
  EXPECT_TRUE(f.will_retry());
  EXPECT_EQ(f.last_quality_code(), 18);
  EXPECT_TRUE(f.has_time());
  EXPECT_EQ(FaultFor(1, Timeout("x"), 1, false, -1, "moving: x").reason(), "moving: x");
}

// --- MeasureReading ----------------------------------------------------------------------------

TEST(MeasureReading, MovesToTheRequiredPoseAndTakesTheFeedbackAsThePose) {
  ScriptedRig r;
  const Pose pose = At(10, -35, 0, 22.5);
  Result<TakenReading> taken = r.Measure(SampleRequest(3, pose));
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  ASSERT_EQ(r.stage->moves().size(), 1u);
  EXPECT_DOUBLE_EQ(*r.stage->moves()[0].alpha, 10);
  EXPECT_FALSE(r.stage->moves()[0].gamma.has_value());  // γ is a dial on this rig
  EXPECT_DOUBLE_EQ(taken->pose.alpha, 10.01);           // the stage's feedback
  EXPECT_DOUBLE_EQ(taken->pose.delta, 22.5);
  EXPECT_TRUE(r.known_stage.At(pose));
  EXPECT_EQ(taken->measurements, 1);
  EXPECT_EQ(taken->report.radiance, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(taken->outcome.note, "as planned");
  EXPECT_EQ(r.known_meter.last_quality, 0);
  ASSERT_EQ(r.meter->configured.size(), 1u);
  EXPECT_EQ(r.meter->configured[0].integration_ms, 250);
  EXPECT_FALSE(r.move.started());
}

TEST(MeasureReading, NeitherMovesNorConfiguresAgainWhenBothAreKnown) {
  ScriptedRig r;
  const Pose pose = At(10, -35);
  ASSERT_TRUE(r.Measure(SampleRequest(3, pose)).ok());
  ASSERT_TRUE(r.Measure(SampleRequest(4, pose)).ok());
  EXPECT_EQ(r.stage->moves().size(), 1u);
  EXPECT_EQ(r.meter->configured.size(), 1u);

  ReadingRequest dark = SampleRequest(5, pose);
  dark.settings.dark = true;  // a change of the dark flag configures the meter again
  ASSERT_TRUE(r.Measure(dark).ok());
  ASSERT_EQ(r.meter->configured.size(), 2u);
  EXPECT_TRUE(r.meter->configured[1].dark);
  EXPECT_TRUE(r.known_meter.dark);
}

TEST(MeasureReading, WithoutARequiredPoseTheStageStaysAndThePoseIsTheStepsOwn) {
  ScriptedRig r;
  ReadingRequest request = SampleRequest(0, At(5, 6));
  request.required.reset();  // sample-fixed: no moves
  Result<TakenReading> taken = r.Measure(request);
  ASSERT_TRUE(taken.ok());
  EXPECT_TRUE(r.stage->moves().empty());
  EXPECT_EQ(taken->pose, At(5, 6));
}

TEST(MeasureReading, AFailedTransferIsRetriedWithTheMeterConfiguredAgain) {
  ScriptedRig r;
  r.meter->transfer_errors = {ProtocolError("garbled report")};
  std::vector<std::string> errors;
  const RetryRunner retry = [&](const std::function<Status(std::uint32_t)>& attempt) {
    Status st = attempt(1);
    if (st.ok()) return st;
    errors.push_back(st.message());
    return attempt(2);
  };
  Result<TakenReading> taken = r.Measure(SampleRequest(3, At(1, 2)), retry);
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("measuring the spectrum of step 3"), std::string::npos) << errors[0];
  EXPECT_EQ(taken->measurements, 2);  // the lost measurement counts too
  EXPECT_EQ(r.meter->configured.size(), 2u);
  EXPECT_EQ(r.stage->moves().size(), 1u);  // the stage was known to be there
}

TEST(MeasureReading, AQualityFailureLeavesItsCodeAsTheLastQuality) {
  ScriptedRig r;
  r.meter->measure_results = {Result<drivers::MeasurementOutcome>(DeviceError(18, "too dark"))};
  Result<TakenReading> taken = r.Measure(SampleRequest(2, At(0, 0)));
  ASSERT_FALSE(taken.ok());
  EXPECT_EQ(taken.status().code(), StatusCode::kDeviceError);
  EXPECT_NE(taken.status().message().find("measuring the spectrum of step 2"), std::string::npos);
  EXPECT_EQ(r.known_meter.last_quality, 18);
}

TEST(MeasureReading, AFailedMoveNamesTheStepAndLeavesTheStageUnknown) {
  ScriptedRig r;
  r.stage->move_errors = {DeviceError(7, "alarm")};
  Result<TakenReading> taken = r.Measure(SampleRequest(6, At(3, 4)));
  ASSERT_FALSE(taken.ok());
  EXPECT_NE(taken.status().message().find("moving to the pose of step 6 before measuring"),
            std::string::npos)
      << taken.status().message();
  EXPECT_FALSE(r.known_stage.target.has_value());
  EXPECT_TRUE(r.meter->configured.empty());
}

TEST(MeasureReading, ALaterAttemptClearsTheStagesAlarmsBeforeMoving) {
  ScriptedRig r;
  r.stage->move_errors = {DeviceError(7, "alarm")};
  r.stage->RaiseAlphaAlarm();
  Result<TakenReading> taken = r.Measure(SampleRequest(6, At(3, 4)), Attempts(2));
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_EQ(r.stage->alarm_resets(), 1);
  EXPECT_EQ(r.stage->moves().size(), 2u);
}

TEST(MeasureReading, ThePipelinedMoveStartsWhileTheSpectrumTransfers) {
  ScriptedRig r;
  bool moved_during_transfer = false;
  r.meter->during_transfer = [&] { moved_during_transfer = r.stage->WaitForMoves(2, 5s); };
  Result<TakenReading> taken = r.Measure(PipelinedRequest());
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  EXPECT_TRUE(moved_during_transfer);
  ASSERT_TRUE(r.move.started());
  EXPECT_EQ(r.move.step_index(), 4);
  EXPECT_FALSE(r.known_stage.target.has_value());  // unknown while the move may run
  r.move.Settle(r.known_stage);
  EXPECT_TRUE(r.move.status().ok());
  EXPECT_TRUE(r.known_stage.At(At(20, 5)));
  EXPECT_DOUBLE_EQ(r.known_stage.feedback.alpha, 20.01);
  EXPECT_DOUBLE_EQ(taken->pose.alpha, 10.01);  // the reading keeps its own pose
}

TEST(MeasureReading, AfterAFailedTransferThePipelinedMoveIsAbandonedAndTheStageMovedBack) {
  ScriptedRig r;
  r.meter->transfer_errors = {Timeout("no report")};
  Result<TakenReading> taken = r.Measure(PipelinedRequest(), Attempts(2));
  ASSERT_TRUE(taken.ok()) << taken.status().ToString();
  r.move.Settle(r.known_stage);
  EXPECT_TRUE(r.known_stage.At(At(20, 5)));
  const std::vector<drivers::StageTarget> moves = r.stage->moves();
  // to the pose, away (pipelined), back to the pose, away again (the second attempt's move)
  ASSERT_EQ(moves.size(), 4u);
  EXPECT_DOUBLE_EQ(*moves[0].alpha, 10);
  EXPECT_DOUBLE_EQ(*moves[1].alpha, 20);
  EXPECT_DOUBLE_EQ(*moves[2].alpha, 10);
  EXPECT_DOUBLE_EQ(*moves[3].alpha, 20);
}

// --- PipelinedMove -----------------------------------------------------------------------------

TEST(PipelinedMove, AFailedMoveLeavesTheStageUnknownAndKeepsItsError) {
  ScriptedRig r;
  r.stage->move_errors = {DeviceError(7, "alarm")};
  StageKnowledge stage;
  stage.target = At(1, 1);
  PipelinedMove move;
  move.Start(*r.rig, 9, At(2, 2), CallContext::WithTimeout(5s), stage);
  EXPECT_FALSE(stage.target.has_value());
  move.Settle(stage);
  move.Settle(stage);  // idempotent
  EXPECT_FALSE(stage.target.has_value());
  EXPECT_EQ(move.status().code(), StatusCode::kDeviceError);
  move.Abandon(stage);
  EXPECT_FALSE(move.started());
}

TEST(PipelinedMove, NotStartedChangesNothing) {
  StageKnowledge stage;
  stage.target = At(1, 1);
  PipelinedMove move;
  move.Settle(stage);
  EXPECT_TRUE(stage.At(At(1, 1)));
  EXPECT_EQ(move.status().code(), StatusCode::kInternal);
}

// --- BuildReadingRecord ------------------------------------------------------------------------

TakenReading Taken(const Pose& pose) {
  TakenReading t;
  t.pose = pose;
  t.report.grid = WavelengthGrid{380, 4, 3};
  t.report.radiance = {1, 2, 3};
  t.outcome.quality_code = 18;
  t.outcome.flagged = true;
  t.outcome.integration_ms = 500;
  t.outcome.note = "doubled to 500 ms";
  t.measurements = 0;
  return t;
}

storage::StepRecord StepOf(storage::StepKind kind, const Pose& pose) {
  storage::StepRecord s;
  s.step_index = 2;
  s.kind = kind;
  s.pose = pose;
  return s;
}

TEST(BuildReadingRecord, ASampleNamesTheLatestReferenceAndDark) {
  RecordSources sources;
  sources.reference = 11;
  sources.dark = 12;
  sources.meter = drivers::MeterIdentity{"PR-650", "SN-42", {}};
  const Pose pose = At(0, 0, 0, 30);
  const storage::ReadingRecord r =
      BuildReadingRecord(StepOf(storage::StepKind::kSample, pose), Taken(pose), sources);
  EXPECT_EQ(r.kind, storage::ReadingKind::kSample);
  EXPECT_EQ(r.reference_reading_id, std::optional<std::int64_t>(11));
  EXPECT_EQ(r.dark_reading_id, std::optional<std::int64_t>(12));
  EXPECT_EQ(r.pose, pose);
  EXPECT_EQ(r.directions, PoseToDirections(pose, sources.convention));
  EXPECT_EQ(r.spectrum, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(r.grid, (WavelengthGrid{380, 4, 3}));
  EXPECT_EQ(r.quality_code, 18);
  EXPECT_TRUE(r.flagged);
  EXPECT_EQ(r.integration_ms, 500);
  EXPECT_EQ(r.note, "doubled to 500 ms");
  EXPECT_EQ(r.attempts, 1);  // at least one, even when the count was lost
  EXPECT_EQ(r.meter_serial, "SN-42");
}

TEST(BuildReadingRecord, AReferenceIsDividedByNothing) {
  RecordSources sources;
  sources.reference = 11;
  sources.dark = 12;
  TakenReading taken = Taken(At(0, 0));
  taken.measurements = 3;
  const storage::ReadingRecord r =
      BuildReadingRecord(StepOf(storage::StepKind::kReference, At(0, 0)), taken, sources);
  EXPECT_EQ(r.kind, storage::ReadingKind::kReference);
  EXPECT_FALSE(r.reference_reading_id.has_value());
  EXPECT_FALSE(r.dark_reading_id.has_value());
  EXPECT_EQ(r.attempts, 3);
  EXPECT_TRUE(r.meter_serial.empty());
}

TEST(BuildReadingRecord, ASampleFixedReadingTakesItsTargetAsDirections) {
  RecordSources sources;
  sources.sample_fixed = true;
  storage::StepRecord step = StepOf(storage::StepKind::kSample, At(0, 0));
  Directions target;
  target.theta_i = 45;
  target.theta_o = 30;
  target.phi_o = 180;
  step.target = target;
  EXPECT_EQ(BuildReadingRecord(step, Taken(At(0, 0)), sources).directions, target);
  sources.sample_fixed = false;
  EXPECT_EQ(BuildReadingRecord(step, Taken(At(0, 0)), sources).directions,
            PoseToDirections(At(0, 0), sources.convention));
}

// --- RecordMeterOnce and the executor's commit (a real SQLite file) ----------------------------

class StoredSession : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(dir.error().empty()) << dir.error();
    Result<std::unique_ptr<storage::SessionStore>> opened =
        storage::SessionStore::Open(dir.file("brdf.db").string());
    ASSERT_TRUE(opened.ok()) << opened.status().ToString();
    store = std::move(*opened);
  }
  std::int64_t Create(std::vector<storage::StepRecord> steps) {
    for (std::size_t i = 0; i < steps.size(); ++i) steps[i].step_index = static_cast<int>(i);
    storage::NewSession s;
    s.name = "reading step";
    s.plan_kind = "pose_list";
    s.plan_json = "{}";
    Result<std::int64_t> id = store->CreateSession(s, steps);
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    if (!id.ok()) return 0;
    const Status running = store->SetSessionState(*id, SessionState::kRunning, "");
    EXPECT_TRUE(running.ok()) << running.ToString();
    return *id;
  }

  testing::TempDir dir{"reading-step-test"};
  std::shared_ptr<storage::SessionStore> store;
};

TEST_F(StoredSession, RecordMeterOnceStoresTheSerialAndTheDeviceOnce) {
  const std::int64_t id = Create({StepOf(storage::StepKind::kReference, At(0, 0))});
  Result<storage::SessionRecord> session = store->GetSession(id);
  ASSERT_TRUE(session.ok());
  MeterKnowledge meter;
  const drivers::MeterIdentity identity{"PR-650", "SN-42", {}};
  RecordMeterOnce(*store, *session, identity, meter);
  EXPECT_TRUE(meter.recorded);
  RecordMeterOnce(*store, *session, drivers::MeterIdentity{"PR-650", "SN-43", {}}, meter);

  Result<storage::SessionRecord> after = store->GetSession(id);
  ASSERT_TRUE(after.ok());
  EXPECT_EQ(after->meter_serial, "SN-42");
  Result<std::vector<storage::DeviceRecord>> devices = store->GetDevices(id);
  ASSERT_TRUE(devices.ok());
  ASSERT_EQ(devices->size(), 1u);
  EXPECT_EQ((*devices)[0].kind, "spectroradiometer");
  EXPECT_EQ((*devices)[0].serial, "SN-42");
}

// A host that lets the session run and keeps what it heard.
class RecordingHost : public ExecutorHost {
 public:
  Result<SessionState> ApplyEvent(std::int64_t, SessionEvent event, const std::string&) override {
    events.push_back(event);
    return event == SessionEvent::kFinish ? SessionState::kCompleted : SessionState::kRunning;
  }
  SessionState CurrentState(std::int64_t) override { return SessionState::kRunning; }
  Result<SessionState> RaisePrompt(std::int64_t, const v1::Prompt&) override {
    return FailedPrecondition("no prompts here");
  }
  void StepCompleted(std::int64_t, const v1::StepCompletion& completion,
                     const storage::ReadingRecord* reading) override {
    completions.push_back(completion);
    readings.push_back(reading != nullptr ? std::optional(*reading) : std::nullopt);
  }
  void Fault(std::int64_t, const v1::Fault& fault) override { faults.push_back(fault); }
  // The stored plan is "{}": every policy defaulted.
  Result<std::shared_ptr<const SessionPlan>> Plan(std::int64_t) override {
    return std::make_shared<const SessionPlan>(MakeSessionPlan(v1::Plan{}));
  }

  std::vector<SessionEvent> events;
  std::vector<v1::StepCompletion> completions;
  std::vector<std::optional<storage::ReadingRecord>> readings;
  std::vector<v1::Fault> faults;
};

TEST_F(StoredSession, TheCommitStoresTheReadingAndHandsItToTheHostWithItsId) {
  const std::int64_t id = Create({StepOf(storage::StepKind::kMove, At(10, 0)),
                                  StepOf(storage::StepKind::kReference, At(10, 0)),
                                  StepOf(storage::StepKind::kMove, At(20, 0)),
                                  StepOf(storage::StepKind::kSample, At(20, 0))});
  ScriptedRig r;
  RecordingHost host;
  Executor::Options options;
  options.pipelining = true;
  Executor executor(id, store, *r.rig, host, options);
  executor.Run();

  ASSERT_TRUE(host.faults.empty()) << host.faults[0].reason();
  // move, reference, move (pipelined: its done mark after the reference's commit), sample
  ASSERT_EQ(host.completions.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(host.completions[i].step_index(), i);
  ASSERT_TRUE(host.readings[1].has_value());
  ASSERT_TRUE(host.readings[3].has_value());
  const storage::ReadingRecord& reference = *host.readings[1];
  const storage::ReadingRecord& sample = *host.readings[3];
  EXPECT_GT(reference.id, 0);
  EXPECT_EQ(reference.session_id, id);
  EXPECT_EQ(reference.step_index, 1);
  EXPECT_EQ(host.completions[1].reading_id(), reference.id);
  EXPECT_EQ(sample.reference_reading_id, std::optional<std::int64_t>(reference.id));
  EXPECT_EQ(sample.meter_serial, "SN-42");
  EXPECT_DOUBLE_EQ(sample.pose.alpha, 20.01);
  EXPECT_EQ(host.events.back(), SessionEvent::kFinish);

  Result<std::vector<storage::ReadingRecord>> stored = store->GetReadings(id, 0, 10);
  ASSERT_TRUE(stored.ok());
  ASSERT_EQ(stored->size(), 2u);
  EXPECT_EQ((*stored)[1].id, sample.id);
  EXPECT_EQ((*stored)[1].reference_reading_id, sample.reference_reading_id);
  EXPECT_EQ((*stored)[1].spectrum, (std::vector<double>{1, 2, 3}));
  // The stage went to 10 and to 20 once each: the pipelined move counted as the move step.
  EXPECT_EQ(r.stage->moves().size(), 2u);
}

TEST(MeterOverloadedTest, KnowsEachMetersOverloadByItsOwnCode) {
  auto meter = [](const std::string& model) {
    return std::optional<drivers::MeterIdentity>(drivers::MeterIdentity{model, "1", {}});
  };
  const Status quality19 = DeviceError(19, "quality 19 (overload)");
  EXPECT_TRUE(MeterOverloaded(meter("PR-650"), quality19));
  EXPECT_TRUE(MeterOverloaded(meter("PR-650"), quality19.WithContext("measuring step 4")));
  EXPECT_FALSE(MeterOverloaded(meter("PR-650"), DeviceError(14, "quality 14")));
  EXPECT_FALSE(MeterOverloaded(meter("PR-650"), DeviceError(10, "quality 10 (weak)")));
  // The CS-2000's ER10 (over the measurement range) is its overload; its own 19 is not.
  EXPECT_TRUE(MeterOverloaded(meter("CS-2000"), DeviceError(10, "ER10")));
  EXPECT_TRUE(MeterOverloaded(meter("CS-2000A"), DeviceError(10, "ER10")));
  EXPECT_FALSE(MeterOverloaded(meter("CS-2000"), DeviceError(19, "ER19")));
  // The PR-670's codes map onto no overload (too dark, sync failures).
  EXPECT_FALSE(MeterOverloaded(meter("PR-670"), DeviceError(-8, "too dark")));
  EXPECT_FALSE(MeterOverloaded(meter("PR-670"), DeviceError(19, "19")));
  // Not a device's code, or no meter known.
  EXPECT_FALSE(MeterOverloaded(meter("PR-650"), Timeout("no reply")));
  EXPECT_FALSE(MeterOverloaded(std::nullopt, quality19));
}

}  // namespace
}  // namespace brdf::daemon
