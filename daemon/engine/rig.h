// The rig: the two instruments (the spectroradiometer and the rotation stage) and a supervisor
// thread that keeps them connected. The daemon starts without them: a device that is absent shows
// as disconnected and is retried with a growing backoff, and the API stays up meanwhile.
//
// Who may talk to a device when. The meter is used by one thread at a time: the executor takes
// it with UseMeter (which also connects it first when needed), the supervisor only touches it
// (connect, identify) when nobody holds it. The stage is thread-safe for moves and reads, but not
// while it connects or disconnects, so UseStage holds a shared lock and the supervisor's
// connect/disconnect an exclusive one. The executor's meter thread and stage thread may each hold
// their device at the same time: that is what lets a move overlap a spectrum transfer.
//
// A call that fails with kDisconnected (or kProtocolError on the meter: the link is in an unknown
// state) marks the device disconnected; the next use (or the supervisor) reconnects it.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "brdf/v1/brdf.pb.h"
#include "core/call_context.h"
#include "core/clock.h"
#include "core/mutex.h"
#include "core/plan/rig_description.h"
#include "core/pose.h"
#include "core/status.h"
#include "core/wavelength_grid.h"
#include "daemon/config/config.h"
#include "daemon/engine/device_gate.h"
#include "drivers/rotation_stage.h"
#include "drivers/spectroradiometer.h"

namespace brdf::daemon {

enum class DeviceConnection { kDisconnected, kConnecting, kConnected, kFault };
const char* DeviceConnectionName(DeviceConnection c);  // "disconnected", "connecting", …

// How one device is doing.
struct DeviceHealth {
  std::string name;     // "meter" or "stage"
  std::string model;    // "PR-650", "Modbus stage (az profile)"
  std::string address;  // serial port or host:port
  DeviceConnection connection = DeviceConnection::kDisconnected;
  std::string last_error;  // the last error seen (kept after a reconnect, for the record)
  std::chrono::system_clock::time_point since{};  // when `connection` last changed
  int failed_attempts = 0;                        // connection attempts failed in a row
};

struct RigStatus {
  DeviceHealth meter;
  DeviceHealth stage;
  std::optional<Pose> live_pose;  // last pose the stage reported; nullopt before the first
  // δ on a rig without a detector arm: where the operator last confirmed the detector.
  std::optional<double> manual_delta_deg;
  std::string meter_serial;                  // from Identify (D110); empty until identified
  std::optional<WavelengthGrid> meter_grid;  // the meter's wavelength layout (D120)
  plan::RigDescription description;          // axes present, travel limits
  std::chrono::system_clock::time_point updated_at{};
};

// The rig status as the API's message (active_session_id left empty for the caller).
v1::RigStatus ToProto(const RigStatus& status);

class Rig {
 public:
  struct DeviceInfo {
    std::string model;    // "PR-650"
    std::string address;  // "/dev/ttyUSB0", "127.0.0.1:1502"
  };
  struct Options {
    // Connection retries: first wait, growth factor, longest wait.
    std::chrono::milliseconds backoff_initial{500};
    double backoff_multiplier = 2;
    std::chrono::milliseconds backoff_max{30000};
    // Longest wait between stage connection attempts: a stage that answers again shows as
    // connected within this plus one attempt ([stage] reconnect_max_ms). A refused TCP connect
    // or a missing serial device fails at once, so short waits cost the rig nothing.
    std::chrono::milliseconds stage_backoff_max{1000};
    // Deadline of one connection attempt (the PR-650's wake-up takes a few seconds).
    std::chrono::milliseconds connect_timeout{15000};
    // How often the supervisor reads the live pose while the stage is connected.
    std::chrono::milliseconds pose_poll_interval{500};
    // Clock for the waits (the supervisor's period, device deadlines).
    const Clock* clock = &Clock::Real();
  };

  // Either device may be null (not configured): it then stays disconnected with a detail saying
  // so, and every use fails with kDisconnected.
  Rig(std::unique_ptr<drivers::Spectroradiometer> meter, DeviceInfo meter_info,
      std::unique_ptr<drivers::RotationStage> stage, DeviceInfo stage_info,
      plan::RigDescription description, Options options);
  // The daemon's rig: the PR-650 on [meter] and the Modbus stage on [stage] (engine_rig_config.cc).
  // Nothing is opened until Start() (the supervisor) or a use. kConfigurationError naming the key
  // when a driver refuses the settings.
  static Result<std::unique_ptr<Rig>> FromConfig(const Config& config, Options options);

  // Stop() and disconnect.
  ~Rig();
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  // Starts / stops the supervisor thread. Start is idempotent. Stop also disconnects both
  // devices (waiting for a holder of UseMeter/UseStage to finish its call).
  void Start();
  void Stop();

  RigStatus GetStatus() const;
  // The operator is looking (rig status) or resuming: a disconnected stage is tried again now
  // (the supervisor is woken for it) instead of at the end of its back-off. Cheap when connected
  // or already connecting; the count of failed attempts goes on (for the log's pace).
  void RetryStageNow();
  const plan::RigDescription& description() const { return description_; }

  // Runs `fn` with the meter held exclusively, connecting it first (within ctx) when it is not
  // connected. Returns fn's Status; errors update the meter's health.
  Status UseMeter(const CallContext& ctx,
                  const std::function<Status(drivers::Spectroradiometer&)>& fn);
  // Runs `fn` with the stage (shared: reads and one move may overlap), connecting it first.
  Status UseStage(const CallContext& ctx, const std::function<Status(drivers::RotationStage&)>& fn);

  // The meter's identity once known (Identify after each connection).
  std::optional<drivers::MeterIdentity> meter_identity() const;

  // Records where the operator says the detector is (rigs without a detector arm).
  void SetManualDelta(double delta_deg);

  // Stops the stage now (pause immediate, abort): does not wait for a mover to finish, the
  // driver's Stop honours only the deadline.
  Status StopStage(std::chrono::milliseconds timeout = std::chrono::seconds(2));

 private:
  void Supervise();
  // One connection attempt of each kind (skipped while a user holds the device).
  void TryConnectMeter();
  void TryConnectStage();
  void PollPose();
  Status ConnectMeterLocked(const CallContext& ctx);  // meter_mu_ held
  Status ConnectStageLocked(const CallContext& ctx);  // stage_mu_ held exclusively
  // Records the outcome of a call or connection attempt in the device's health.
  void NoteMeterResult(const Status& status, bool connecting);
  void NoteStageResult(const Status& status, bool connecting);
  void SetConnection(DeviceHealth& health, DeviceConnection connection) REQUIRES(status_mu_);
  std::chrono::milliseconds BackoffAfter(int failed_attempts, std::chrono::milliseconds cap) const;

  plan::RigDescription description_;
  Options options_;
  std::unique_ptr<drivers::Spectroradiometer> meter_;
  std::unique_ptr<drivers::RotationStage> stage_;

  // Held while a meter call runs; a caller waits no longer than its context.
  DeviceGate meter_mu_;
  // Shared: calls; exclusive: connect / disconnect.
  DeviceGate stage_mu_;
  std::atomic<bool> stage_reset_requested_{false};  // the link failed under a call: reconnect

  mutable Mutex status_mu_;
  RigStatus status_ GUARDED_BY(status_mu_);
  std::optional<drivers::MeterIdentity> identity_ GUARDED_BY(status_mu_);
  std::chrono::steady_clock::time_point next_meter_attempt_ GUARDED_BY(status_mu_){};
  std::chrono::steady_clock::time_point next_stage_attempt_ GUARDED_BY(status_mu_){};

  Mutex thread_mu_;
  CondVar wake_;
  bool stopping_ GUARDED_BY(thread_mu_) = false;
  bool retry_now_ GUARDED_BY(thread_mu_) = false;  // RetryStageNow: end the supervisor's wait
  std::thread supervisor_;
  CancelToken supervisor_cancel_;
};

}  // namespace brdf::daemon
