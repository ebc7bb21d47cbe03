#include "daemon/engine/rig.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <shared_mutex>
#include <utility>

#include "daemon/wire/values.h"

namespace brdf::daemon {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;

// How long a caller waits for a device another thread holds before looking at its context again.
constexpr milliseconds kLockSlice{20};

v1::ConnectionState ToProto(DeviceConnection c) {
  switch (c) {
    case DeviceConnection::kConnected:
      return v1::CONNECTION_STATE_CONNECTED;
    case DeviceConnection::kConnecting:
      return v1::CONNECTION_STATE_CONNECTING;
    case DeviceConnection::kDisconnected:
      return v1::CONNECTION_STATE_DISCONNECTED;
    case DeviceConnection::kFault:
      return v1::CONNECTION_STATE_FAULT;
  }
  return v1::CONNECTION_STATE_UNSPECIFIED;
}

// Errors after which the link is in an unknown state and must be opened again: a vanished port,
// a meter that stopped answering (it may have left remote mode: Connect wakes it again).
bool LinkLost(const Status& s) {
  return s.code() == StatusCode::kDisconnected || s.code() == StatusCode::kTimeout;
}

// Errors that are the device's own (an alarm, a quality code): the link is fine.
bool DeviceFault(const Status& s) {
  return s.code() == StatusCode::kDeviceError;
}

// Waits for a timed lock without outliving the context.
template <typename TryLock>
Status AcquireWithin(const CallContext& ctx, const char* device, TryLock try_lock) {
  while (!try_lock(kLockSlice)) {
    if (ctx.cancelled())
      return Cancelled(std::string(device) + ": cancelled while waiting for " + "the device (" +
                       ctx.cancel().reason() + ")");
    if (ctx.expired())
      return Timeout(std::string(device) +
                     ": busy (another call or a connection attempt holds it) until the deadline");
  }
  return Status::Ok();
}

}  // namespace

const char* DeviceConnectionName(DeviceConnection c) {
  switch (c) {
    case DeviceConnection::kDisconnected:
      return "disconnected";
    case DeviceConnection::kConnecting:
      return "connecting";
    case DeviceConnection::kConnected:
      return "connected";
    case DeviceConnection::kFault:
      return "fault";
  }
  return "unknown";
}

v1::RigStatus ToProto(const RigStatus& status) {
  v1::RigStatus out;
  for (const DeviceHealth* h : {&status.meter, &status.stage}) {
    v1::DeviceStatus* d = out.add_devices();
    d->set_name(h->name);
    d->set_model(h->model);
    d->set_address(h->address);
    d->set_state(ToProto(h->connection));
    std::string detail = h->connection == DeviceConnection::kConnected
                             ? std::string("connected")
                             : std::string(DeviceConnectionName(h->connection));
    if (!h->last_error.empty()) detail += "; last error: " + h->last_error;
    d->set_detail(detail);
  }
  Pose pose = status.live_pose.value_or(Pose{});
  if (!status.description.has_detector_arm && status.manual_delta_deg.has_value()) {
    pose.delta = *status.manual_delta_deg;
  }
  *out.mutable_live_pose() = ToProtoPose(pose);
  out.set_live_pose_valid(status.live_pose.has_value());
  const plan::RigDescription& rig = status.description;
  struct AxisRow {
    const char* name;
    bool present;
    double position;
    const plan::AxisTravel* travel;
  };
  const AxisRow rows[] = {{"alpha", true, pose.alpha, &rig.alpha},
                          {"beta", true, pose.beta, &rig.beta},
                          {"gamma", rig.has_gamma_axis, pose.gamma, &rig.gamma},
                          {"delta", rig.has_detector_arm, pose.delta, &rig.delta}};
  for (const AxisRow& row : rows) {
    v1::AxisStatus* a = out.add_axes();
    a->set_name(row.name);
    a->set_present(row.present);
    a->set_position_deg(row.position);
    a->set_min_deg(row.travel->min_deg);
    a->set_max_deg(row.travel->max_deg);
  }
  out.set_meter_serial(status.meter_serial);
  out.set_detector_arm_motorized(rig.has_detector_arm);
  *out.mutable_updated_at() = ToTimestamp(status.updated_at);
  return out;
}

Rig::Rig(std::unique_ptr<drivers::Spectroradiometer> meter, DeviceInfo meter_info,
         std::unique_ptr<drivers::RotationStage> stage, DeviceInfo stage_info,
         plan::RigDescription description, Options options)
    : description_(std::move(description)),
      options_(options),
      meter_(std::move(meter)),
      stage_(std::move(stage)) {
  const auto now = std::chrono::system_clock::now();
  status_.meter = DeviceHealth{"meter",
                               meter_info.model,
                               meter_info.address,
                               DeviceConnection::kDisconnected,
                               meter_ ? "" : "no meter configured",
                               now,
                               0};
  status_.stage = DeviceHealth{"stage",
                               stage_info.model,
                               stage_info.address,
                               DeviceConnection::kDisconnected,
                               stage_ ? "" : "no stage configured",
                               now,
                               0};
  status_.description = description_;
  status_.updated_at = now;
}

Rig::~Rig() {
  Stop();
}

void Rig::Start() {
  MutexLock lock(thread_mu_);
  if (supervisor_.joinable()) return;
  stopping_ = false;
  supervisor_cancel_ = CancelToken();
  supervisor_ = std::thread([this] { Supervise(); });
}

void Rig::Stop() {
  {
    MutexLock lock(thread_mu_);
    stopping_ = true;
    supervisor_cancel_.Cancel("the daemon is shutting down");
  }
  wake_.NotifyAll();
  if (supervisor_.joinable()) supervisor_.join();
  // Close the devices once their users are done with them.
  if (meter_) {
    std::lock_guard lock(meter_mu_);
    meter_->Disconnect();
  }
  if (stage_) {
    std::unique_lock lock(stage_mu_);
    stage_->Disconnect();
  }
  MutexLock lock(status_mu_);
  if (meter_) SetConnection(status_.meter, DeviceConnection::kDisconnected);
  if (stage_) SetConnection(status_.stage, DeviceConnection::kDisconnected);
}

RigStatus Rig::GetStatus() const {
  MutexLock lock(status_mu_);
  return status_;
}

std::optional<drivers::MeterIdentity> Rig::meter_identity() const {
  MutexLock lock(status_mu_);
  return identity_;
}

void Rig::SetManualDelta(double delta_deg) {
  MutexLock lock(status_mu_);
  status_.manual_delta_deg = delta_deg;
}

void Rig::SetConnection(DeviceHealth& health, DeviceConnection connection) {
  const auto now = std::chrono::system_clock::now();
  if (health.connection != connection) {
    health.connection = connection;
    health.since = now;
  }
  status_.updated_at = now;
}

void Rig::RetryStageNow() {
  if (!stage_) return;
  {
    MutexLock lock(status_mu_);
    if (status_.stage.connection != DeviceConnection::kDisconnected) return;
    next_stage_attempt_ = steady_clock::now();
  }
  {
    MutexLock lock(thread_mu_);
    retry_now_ = true;
  }
  wake_.NotifyAll();
}

std::chrono::milliseconds Rig::BackoffAfter(int failed_attempts, milliseconds cap) const {
  double ms = static_cast<double>(options_.backoff_initial.count()) *
              std::pow(options_.backoff_multiplier, std::max(0, failed_attempts - 1));
  ms = std::min(ms, static_cast<double>(cap.count()));
  return milliseconds(static_cast<std::int64_t>(ms));
}

void Rig::NoteMeterResult(const Status& status, bool connecting) {
  MutexLock lock(status_mu_);
  DeviceHealth& h = status_.meter;
  if (status.ok()) {
    h.failed_attempts = 0;
    SetConnection(h, DeviceConnection::kConnected);
    return;
  }
  if (status.code() == StatusCode::kCancelled) return;  // says nothing about the device
  h.last_error = status.ToString();
  if (connecting || LinkLost(status)) {
    ++h.failed_attempts;
    SetConnection(h, DeviceConnection::kDisconnected);
    next_meter_attempt_ =
        steady_clock::now() + BackoffAfter(h.failed_attempts, options_.backoff_max);
  } else if (DeviceFault(status)) {
    SetConnection(h, DeviceConnection::kFault);
  }
}

void Rig::NoteStageResult(const Status& status, bool connecting) {
  MutexLock lock(status_mu_);
  DeviceHealth& h = status_.stage;
  if (status.ok()) {
    h.failed_attempts = 0;
    SetConnection(h, DeviceConnection::kConnected);
    return;
  }
  if (status.code() == StatusCode::kCancelled) return;
  h.last_error = status.ToString();
  if (connecting || status.code() == StatusCode::kDisconnected) {
    ++h.failed_attempts;
    SetConnection(h, DeviceConnection::kDisconnected);
    next_stage_attempt_ =
        steady_clock::now() +
        BackoffAfter(h.failed_attempts, std::min(options_.backoff_max, options_.stage_backoff_max));
    if (!connecting) stage_reset_requested_ = true;
  } else if (DeviceFault(status)) {
    SetConnection(h, DeviceConnection::kFault);
  }
}

Status Rig::ConnectMeterLocked(const CallContext& ctx) {
  std::string address;
  {
    MutexLock lock(status_mu_);
    SetConnection(status_.meter, DeviceConnection::kConnecting);
    address = status_.meter.address;
  }
  Status st = meter_->Connect(ctx);
  if (st.ok()) {
    Result<drivers::MeterIdentity> id = meter_->Identify(ctx);
    if (id.ok()) {
      MutexLock lock(status_mu_);
      identity_ = *id;
      status_.meter_serial = id->serial_number;
      status_.meter_grid = id->grid;
      if (!id->model.empty()) status_.meter.model = id->model;
    } else {
      st = id.status().WithContext("identifying the meter after connecting");
      meter_->Disconnect();
    }
  }
  NoteMeterResult(st, /*connecting=*/true);
  if (st.ok()) {
    spdlog::info("meter connected ({}, serial {})", address,
                 meter_identity() ? meter_identity()->serial_number : "?");
  } else if (st.code() != StatusCode::kCancelled) {
    spdlog::warn("meter on {} not connected: {}", address, st.ToString());
  }
  return st;
}

Status Rig::ConnectStageLocked(const CallContext& ctx) {
  std::string address;
  {
    MutexLock lock(status_mu_);
    SetConnection(status_.stage, DeviceConnection::kConnecting);
    address = status_.stage.address;
  }
  if (stage_reset_requested_.exchange(false) || stage_->connected()) stage_->Disconnect();
  const Status st = stage_->Connect(ctx);
  NoteStageResult(st, /*connecting=*/true);
  if (st.ok()) {
    spdlog::info("stage connected ({})", address);
  } else if (st.code() != StatusCode::kCancelled) {
    // Attempts come every reconnect_max_ms (1 s) while the stage is away: warn on the first
    // failure and then once a minute or so, the rest at debug level.
    int failed = 0;
    {
      MutexLock lock(status_mu_);
      failed = status_.stage.failed_attempts;
    }
    spdlog::log(failed <= 1 || failed % 60 == 0 ? spdlog::level::warn : spdlog::level::debug,
                "stage on {} not connected (attempt {} in a row): {}", address, failed,
                st.ToString());
  }
  return st;
}

Status Rig::UseMeter(const CallContext& ctx,
                     const std::function<Status(drivers::Spectroradiometer&)>& fn) {
  if (!meter_) return Disconnected("meter: none configured; add a [meter] section to the config");
  BRDF_RETURN_IF_ERROR(
      AcquireWithin(ctx, "meter", [this](milliseconds d) { return meter_mu_.try_lock_for(d); }));
  std::lock_guard lock(meter_mu_, std::adopt_lock);
  if (!meter_->connected()) {
    BRDF_RETURN_IF_ERROR(ConnectMeterLocked(ctx).WithContext("connecting the meter"));
  }
  const Status st = fn(*meter_);
  if (LinkLost(st)) meter_->Disconnect();  // the next use wakes it again
  NoteMeterResult(st, /*connecting=*/false);
  return st;
}

Status Rig::UseStage(const CallContext& ctx,
                     const std::function<Status(drivers::RotationStage&)>& fn) {
  if (!stage_) return Disconnected("stage: none configured; add a [stage] section to the config");
  for (;;) {
    BRDF_RETURN_IF_ERROR(AcquireWithin(
        ctx, "stage", [this](milliseconds d) { return stage_mu_.try_lock_shared_for(d); }));
    std::shared_lock shared(stage_mu_, std::adopt_lock);
    if (stage_->connected() && !stage_reset_requested_) {
      const Status st = fn(*stage_);
      NoteStageResult(st, /*connecting=*/false);
      return st;
    }
    shared.unlock();
    BRDF_RETURN_IF_ERROR(
        AcquireWithin(ctx, "stage", [this](milliseconds d) { return stage_mu_.try_lock_for(d); }));
    std::unique_lock exclusive(stage_mu_, std::adopt_lock);
    if (!stage_->connected() || stage_reset_requested_) {
      BRDF_RETURN_IF_ERROR(ConnectStageLocked(ctx).WithContext("connecting the stage"));
    }
  }
}

Status Rig::StopStage(std::chrono::milliseconds timeout) {
  if (!stage_) return Status::Ok();
  // Do not queue behind a connection attempt: a stage that is connecting is not moving.
  if (!stage_mu_.try_lock_shared_for(std::min(timeout, milliseconds(200)))) return Status::Ok();
  std::shared_lock shared(stage_mu_, std::adopt_lock);
  if (!stage_->connected()) return Status::Ok();
  return stage_->Stop(CallContext::WithTimeout(timeout, CancelToken(), *options_.clock));
}

void Rig::TryConnectMeter() {
  if (!meter_mu_.try_lock()) return;  // in use: it is connected or its user connects it
  std::lock_guard lock(meter_mu_, std::adopt_lock);
  if (meter_->connected()) return;
  (void)ConnectMeterLocked(
      CallContext::WithTimeout(options_.connect_timeout, supervisor_cancel_, *options_.clock));
}

void Rig::TryConnectStage() {
  if (!stage_mu_.try_lock()) return;
  std::unique_lock lock(stage_mu_, std::adopt_lock);
  if (stage_->connected() && !stage_reset_requested_) return;
  (void)ConnectStageLocked(
      CallContext::WithTimeout(options_.connect_timeout, supervisor_cancel_, *options_.clock));
}

void Rig::PollPose() {
  if (!stage_mu_.try_lock_shared()) return;
  std::shared_lock lock(stage_mu_, std::adopt_lock);
  if (!stage_->connected()) return;
  Result<Pose> pose = stage_->ReadPose(
      CallContext::WithTimeout(std::max(options_.pose_poll_interval, milliseconds(1000)),
                               supervisor_cancel_, *options_.clock));
  if (pose.ok()) {
    MutexLock status_lock(status_mu_);
    status_.live_pose = *pose;
    status_.updated_at = std::chrono::system_clock::now();
    if (status_.stage.connection != DeviceConnection::kConnected &&
        status_.stage.connection != DeviceConnection::kFault) {
      SetConnection(status_.stage, DeviceConnection::kConnected);
    }
    return;
  }
  NoteStageResult(pose.status(), /*connecting=*/false);
}

void Rig::Supervise() {
  for (;;) {
    {
      MutexLock lock(thread_mu_);
      if (stopping_) return;
    }
    const auto now = steady_clock::now();
    steady_clock::time_point meter_at, stage_at;
    {
      MutexLock lock(status_mu_);
      meter_at = next_meter_attempt_;
      stage_at = next_stage_attempt_;
    }
    if (meter_ && now >= meter_at) TryConnectMeter();
    if (stage_ && now >= stage_at) TryConnectStage();
    if (stage_) PollPose();

    // Sleep until the next poll or connection attempt, whichever comes first.
    auto wait = options_.pose_poll_interval;
    {
      MutexLock lock(status_mu_);
      const auto after = steady_clock::now();
      if (meter_ && status_.meter.connection != DeviceConnection::kConnected) {
        wait = std::min(wait, std::chrono::duration_cast<milliseconds>(std::max(
                                  next_meter_attempt_ - after, steady_clock::duration(0))));
      }
      if (stage_ && status_.stage.connection != DeviceConnection::kConnected) {
        wait = std::min(wait, std::chrono::duration_cast<milliseconds>(std::max(
                                  next_stage_attempt_ - after, steady_clock::duration(0))));
      }
    }
    wait = std::max(wait, milliseconds(10));
    MutexLock lock(thread_mu_);
    wake_.WaitFor(thread_mu_, wait,
                  [this]() REQUIRES(thread_mu_) { return stopping_ || retry_now_; });
    if (stopping_) return;
    retry_now_ = false;
  }
}

}  // namespace brdf::daemon
