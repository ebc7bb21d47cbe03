// In-process stand-ins for the two instruments, behind the driver interfaces
// (drivers/spectroradiometer.h, drivers/rotation_stage.h), for tests of what sits above the
// drivers: the rig, the executor, the session manager. Like ros2_control's
// mock_components::GenericSystem they keep state without any wire: the stage "moves" by waiting
// distance / speed (scaled), and the meter's spectrum is derived from the stage's pose and from
// what is mounted in front of it, so readings differ from pose to pose and interpolate smoothly.
// Tests that exercise the real drivers and their wire protocols use brdf-sim instead
// (tests/support/sim/rig.h).
//
// Fault injection, set at any time from the test's thread: fail the next N calls with a given
// Status, delay every call, drop the link (and refuse to reconnect while unreachable). Waits
// honour the CallContext: kCancelled when it is cancelled, kTimeout at its deadline.
//
// Threading: the meter is used by one thread at a time (as the interface says), the stage from
// any; the shared FakeBench and the fault setters are safe from any thread.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/call_context.h"
#include "core/geometry.h"
#include "core/pose.h"
#include "core/status.h"
#include "drivers/rotation_stage.h"
#include "drivers/spectroradiometer.h"

namespace brdf::testing {

// What is in front of the meter (brdf-sim's control unit has the same three choices).
enum class FakeTarget { kSample, kWhite, kDark };

// The bench the two fakes share: the pose the stage holds and what is mounted.
class FakeBench {
 public:
  void SetMounted(FakeTarget target);
  FakeTarget mounted() const;
  void SetPose(const Pose& pose);
  Pose pose() const;

 private:
  mutable std::mutex mu_;
  FakeTarget mounted_ = FakeTarget::kSample;
  Pose pose_;
};

// Faults of one fake device; a default-constructed one is a healthy device.
struct FakeFaults {
  int fail_next = 0;  // the next N measurements (meter) or moves (stage) fail with `failure`
  Status failure = DeviceError(14, "fake device: injected failure");
  std::chrono::milliseconds delay{0};  // added to every measurement or move
  bool unreachable = false;            // Connect fails; a connected device drops on its next call
  // Meter: from measurement number `grid_after_calls` + 1 on (counted as FakeCounts::calls), the
  // spectra are on this grid instead of the meter's own: a meter of another model put in
  // mid-session.
  std::optional<WavelengthGrid> grid;
  int grid_after_calls = 0;
};

// Counts of what a fake was asked to do (for assertions on the traffic).
struct FakeCounts {
  int connects = 0;
  int calls = 0;     // measurements (meter) or moves (stage) attempted
  int failures = 0;  // of those, failed by an injected fault
};

// Holds the faults and counts of one fake; the fakes share it with the test.
class FakeFaultSwitch {
 public:
  void Set(const FakeFaults& faults);
  FakeFaults faults() const;
  FakeCounts counts() const;

  // For the fakes: an injected failure for this call, or Ok (and counts the call).
  Status TakeCall();
  void CountConnect();
  bool unreachable() const;

 private:
  mutable std::mutex mu_;
  FakeFaults faults_;
  FakeCounts counts_;
};

// Waits `d` (already scaled) under `ctx`: Ok, kCancelled or kTimeout.
Status FakeWait(std::chrono::steady_clock::duration d, const CallContext& ctx);

struct FakeMeterOptions {
  std::string serial_number = "FAKE650-0001";
  WavelengthGrid grid = WavelengthGrid::Pr650();
  // Simulated time runs this many times faster: a measurement waits integration × averages / it.
  double time_scale = 50;
  // Integration used when the settings ask for adaptive (0).
  int adaptive_integration_ms = 250;
  HolderConvention convention;
};

class FakeMeter : public drivers::Spectroradiometer {
 public:
  FakeMeter(std::shared_ptr<FakeBench> bench, std::shared_ptr<FakeFaultSwitch> faults,
            FakeMeterOptions options = {});

  Status Connect(const CallContext& ctx) override;
  void Disconnect() override;
  bool connected() const override { return connected_; }
  Result<drivers::MeterIdentity> Identify(const CallContext& ctx) override;
  Status Configure(const drivers::MeasurementSettings& settings, const CallContext& ctx) override;
  Result<drivers::MeasurementOutcome> Measure(const CallContext& ctx) override;
  Result<drivers::SpectrumReport> TransferSpectrum(const CallContext& ctx) override;

  // The radiance the fake reports for `target` at `pose` at wavelength `nm` (what Measure takes).
  static double Radiance(FakeTarget target, const Directions& d, double nm);

 private:
  Status CheckLink();

  std::shared_ptr<FakeBench> bench_;
  std::shared_ptr<FakeFaultSwitch> faults_;
  FakeMeterOptions options_;
  std::atomic<bool> connected_{false};
  drivers::MeasurementSettings settings_;
  bool held_ = false;  // a measurement is waiting to be transferred
  drivers::SpectrumReport last_;
};

struct FakeStageOptions {
  bool has_gamma = false;
  bool has_delta = true;
  double speed_deg_s = 30;
  double time_scale = 50;
  double min_deg[4] = {0, -180, -180, 0};
  double max_deg[4] = {90, 180, 180, 180};
};

class FakeStage : public drivers::RotationStage {
 public:
  FakeStage(std::shared_ptr<FakeBench> bench, std::shared_ptr<FakeFaultSwitch> faults,
            FakeStageOptions options = {});

  Status Connect(const CallContext& ctx) override;
  void Disconnect() override;
  bool connected() const override { return connected_; }
  bool HasAxis(drivers::Axis axis) const override;
  Status MoveTo(const drivers::StageTarget& target, const CallContext& ctx) override;
  Result<drivers::AxisState> ReadAxis(drivers::Axis axis, const CallContext& ctx) override;
  Result<Pose> ReadPose(const CallContext& ctx) override;
  Status ResetAlarm(drivers::Axis axis, const CallContext& ctx) override;
  Status Home(drivers::Axis axis, const CallContext& ctx) override;
  Status Stop(const CallContext& ctx) override;

 private:
  Status CheckLink();

  std::shared_ptr<FakeBench> bench_;
  std::shared_ptr<FakeFaultSwitch> faults_;
  FakeStageOptions options_;
  std::atomic<bool> connected_{false};
  CancelToken stop_;  // replaced on each Stop(): a running move ends
  std::mutex stop_mu_;
};

}  // namespace brdf::testing
