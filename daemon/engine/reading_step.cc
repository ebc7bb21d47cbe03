#include "daemon/engine/reading_step.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "drivers/cs2000/protocol.h"
#include "drivers/pr670/protocol.h"

namespace brdf::daemon {

bool MeterOverloaded(const std::optional<drivers::MeterIdentity>& meter, const Status& failure) {
  constexpr int kOverload = 19;  // the PR-650's quality code the policy is keyed by
  if (!meter.has_value() || failure.code() != StatusCode::kDeviceError) return false;
  const std::string& model = meter->model;
  const int code = failure.device_code();
  if (model == "PR-650") return code == kOverload;
  if (model.rfind("CS-", 0) == 0) return drivers::cs2000::PolicyCodeFor(code) == kOverload;
  if (model.rfind("PR-6", 0) == 0) return drivers::pr670::PolicyCodeFor(code) == kOverload;
  return false;
}

Result<Pose> MoveStageTo(Rig& rig, const Pose& pose, const CallContext& ctx) {
  Pose reached = pose;
  const Status st = rig.UseStage(ctx, [&](drivers::RotationStage& stage) {
    drivers::StageTarget target;
    target.alpha = pose.alpha;
    target.beta = pose.beta;
    if (stage.HasAxis(drivers::Axis::kGamma)) target.gamma = pose.gamma;
    if (stage.HasAxis(drivers::Axis::kDelta)) target.delta = pose.delta;
    BRDF_RETURN_IF_ERROR(stage.MoveTo(target, ctx));
    Result<Pose> feedback = stage.ReadPose(ctx);
    if (feedback.ok()) {
      reached.alpha = feedback->alpha;
      reached.beta = feedback->beta;
      if (target.gamma.has_value()) reached.gamma = feedback->gamma;
      if (target.delta.has_value()) reached.delta = feedback->delta;
    }
    return Status::Ok();
  });
  if (!st.ok()) return st;
  return reached;
}

void ResetStageAlarms(Rig& rig, std::int64_t session, const CallContext& ctx) {
  (void)rig.UseStage(ctx, [&](drivers::RotationStage& stage) {
    for (drivers::Axis axis : drivers::kAllAxes) {
      if (!stage.HasAxis(axis)) continue;
      Result<drivers::AxisState> state = stage.ReadAxis(axis, ctx);
      if (state.ok() && state->alarm) {
        const Status reset = stage.ResetAlarm(axis, ctx);
        spdlog::info("session {}: reset the {} alarm (code {}) before retrying: {}", session,
                     drivers::AxisName(axis), state->alarm_code,
                     reset.ok() ? "ok" : reset.ToString());
      }
    }
    return Status::Ok();
  });
}

void PipelinedMove::Start(Rig& rig, int step_index, const Pose& target, const CallContext& ctx,
                          StageKnowledge& stage) {
  step_index_ = step_index;
  target_ = target;
  stage.target.reset();
  thread_ =
      std::thread([this, &rig, target, ctx] { result_.emplace(MoveStageTo(rig, target, ctx)); });
}

void PipelinedMove::Join() {
  if (thread_.joinable()) thread_.join();
}

void PipelinedMove::Settle(StageKnowledge& stage) {
  if (!started()) return;
  Join();
  if (result_.has_value() && result_->ok()) {
    stage.target = target_;
    stage.feedback = result_->value();
  } else {
    stage.target.reset();
  }
}

Status PipelinedMove::status() const {
  if (!result_.has_value()) return Internal("pipelined move left no result");
  return result_->status();
}

void PipelinedMove::Abandon(StageKnowledge& stage) {
  Settle(stage);
  step_index_ = -1;
  result_.reset();
}

drivers::MeasurementSettings MeterSettingsFor(const plan::MeasurementChoice& measurement,
                                              storage::StepKind kind) {
  drivers::MeasurementSettings settings;
  settings.integration_ms = static_cast<int>(measurement.integration_ms);
  settings.averages = static_cast<int>(std::max<std::uint32_t>(1, measurement.averages));
  // A dark is weak by nature: the driver accepts its low-light codes instead of failing them.
  settings.dark = kind == storage::StepKind::kDark;
  return settings;
}

namespace {

// One attempt's meter work: configure when needed, then measure and transfer, starting the
// pipelined move in between.
Status MeasureOnce(const ReadingDevices& devices, const ReadingRequest& request,
                   std::uint32_t attempt, const CallContext& ctx, StageKnowledge& stage,
                   MeterKnowledge& meter, PipelinedMove& move, TakenReading& taken) {
  return devices.rig.UseMeter(ctx, [&](drivers::Spectroradiometer& device) -> Status {
    if (!meter.configured || attempt > 1 || meter.dark != request.settings.dark) {
      BRDF_RETURN_IF_ERROR(
          device.Configure(request.settings, ctx).WithContext("configuring the meter"));
      meter.configured = true;
      meter.dark = request.settings.dark;
    }
    // Called once the meter holds an accepted measurement, while its spectrum still streams in.
    auto measured = [&](const drivers::MeasurementOutcome& done) {
      meter.last_quality = done.quality_code;
      taken.measurements += done.attempts;  // counted even if the transfer then fails
      if (!request.pipelined_step.has_value()) return;
      // The stage may leave now: the measurement is taken, only its transfer is left.
      spdlog::debug("session {}: step {} moves while step {} transfers", devices.session,
                    *request.pipelined_step, request.step_index);
      move.Start(devices.rig, *request.pipelined_step, request.pipelined_pose, ctx, stage);
    };
    Result<drivers::MeasuredSpectrum> spectrum = device.MeasureSpectrum(ctx, measured);
    if (!spectrum.ok()) {
      if (spectrum.status().code() == StatusCode::kDeviceError) {
        meter.last_quality = spectrum.status().device_code();
      }
      return spectrum.status().WithContext("measuring the spectrum of " + request.step_name);
    }
    taken.outcome = spectrum->outcome;
    taken.report = std::move(spectrum->report);
    return Status::Ok();
  });
}

}  // namespace

Result<TakenReading> MeasureReading(const ReadingDevices& devices, const plan::RigDescription& rig,
                                    const ReadingRequest& request, const RetryRunner& retry,
                                    StageKnowledge& stage, MeterKnowledge& meter,
                                    PipelinedMove& move) {
  TakenReading taken;
  taken.pose = request.pose;
  const Status st = retry([&](std::uint32_t attempt) -> Status {
    const CallContext ctx = devices.call_context();
    if (move.started()) move.Abandon(stage);  // a failed attempt's move: move back below
    if (request.required.has_value() && !stage.At(*request.required)) {
      if (attempt > 1) ResetStageAlarms(devices.rig, devices.session, ctx);
      stage.target.reset();
      Result<Pose> reached = MoveStageTo(devices.rig, *request.required, ctx);
      if (!reached.ok()) {
        return reached.status().WithContext("moving to the pose of " + request.step_name +
                                            " before measuring");
      }
      stage.target = *request.required;
      stage.feedback = *reached;
    }
    if (request.required.has_value()) {
      taken.pose.alpha = stage.feedback.alpha;
      taken.pose.beta = stage.feedback.beta;
      if (rig.has_gamma_axis) taken.pose.gamma = stage.feedback.gamma;
      if (rig.has_detector_arm) taken.pose.delta = stage.feedback.delta;
    }
    return MeasureOnce(devices, request, attempt, ctx, stage, meter, move, taken);
  });
  if (!st.ok()) return st;
  return taken;
}

storage::ReadingRecord BuildReadingRecord(const storage::StepRecord& step, TakenReading taken,
                                          const RecordSources& sources) {
  storage::ReadingRecord reading;
  reading.kind = storage::ReadingKindFor(step.kind).value_or(storage::ReadingKind::kSample);
  reading.pose = taken.pose;
  if (sources.sample_fixed && step.target.has_value()) {
    reading.directions = *step.target;  // lamp and detector were placed by hand at the target
  } else {
    reading.directions = PoseToDirections(taken.pose, sources.convention);
  }
  reading.grid = taken.report.grid;
  reading.spectrum = std::move(taken.report.radiance);
  reading.quality_code = taken.outcome.quality_code;
  reading.flagged = taken.outcome.flagged;
  reading.integration_ms = taken.outcome.integration_ms;
  reading.attempts = std::max(1, taken.measurements);
  reading.note = taken.outcome.note;
  if (reading.kind == storage::ReadingKind::kSample) {
    reading.reference_reading_id = sources.reference;
    reading.dark_reading_id = sources.dark;
  }
  if (sources.meter.has_value()) reading.meter_serial = sources.meter->serial_number;
  return reading;
}

void RecordMeterOnce(storage::SessionStore& store, const storage::SessionRecord& session,
                     const drivers::MeterIdentity& identity, MeterKnowledge& meter) {
  if (meter.recorded) return;
  meter.recorded = true;
  if (session.meter_serial != identity.serial_number) {
    (void)store.SetSessionMeterSerial(session.id, identity.serial_number);
  }
  storage::DeviceRecord device;
  device.session_id = session.id;
  device.kind = "spectroradiometer";
  device.model = identity.model;
  device.serial = identity.serial_number;
  (void)store.RecordDevice(device);
}

}  // namespace brdf::daemon
