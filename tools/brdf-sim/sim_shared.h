// What the parts of brdf-sim share: the simulated clock scale, what is mounted in front of the
// meter, the faults to inject, and the two seams between the endpoints and the optical model.
//
//   PR-650 endpoint (pty) ──MeterBackend──▶ optics (lamp, sample, white, dark, noise)
//                                               │ StagePoseSource
//   Modbus endpoint (TCP, RTU pty) ─────────────┘ (live axis positions)
//   control unit id ──▶ SimControl (mounted target, faults), read by both endpoints
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <vector>

#include "core/pose.h"

namespace brdf::sim {

// Simulated durations run `factor` times faster than real time (factor 1 = real time).
struct TimeScale {
  double factor = 1.0;
  std::chrono::nanoseconds ToReal(double sim_seconds) const {
    return std::chrono::nanoseconds(static_cast<std::int64_t>(sim_seconds / factor * 1e9));
  }
  double ToSim(std::chrono::nanoseconds real) const { return real.count() * 1e-9 * factor; }
};

enum class MountedTarget : int { kSample = 0, kWhite = 1, kDark = 2 };

// The meter's setup as the meter endpoints understand it (the PR-650's S command, the PR-670's
// SE and SN, the CS-2000's SPMS).
struct MeterSetup {
  int integration_ms = 0;  // 0 = adaptive
  int averages = 1;
};

struct SimMeasurement {
  int quality_code = 0;          // 0, or 10/18/19 from the light level, or an injected code
  int integration_ms = 0;        // what the meter used (adaptive picks one from the light level)
  double duration_s = 0;         // simulated time the measurement takes
  std::vector<double> radiance;  // 101 values, 380–780 nm every 4 nm, W·m⁻²·sr⁻¹·nm⁻¹
  double integrated = 0;         // integrated radiance (the D5 intensity line)
};

// Implemented by the optical model: what the meter would read right now.
class MeterBackend {
 public:
  virtual ~MeterBackend() = default;
  virtual SimMeasurement Measure(const MeterSetup& setup) = 0;
};

// Implemented by the stage simulator: where the axes are right now (degrees, α β γ δ).
class StagePoseSource {
 public:
  virtual ~StagePoseSource() = default;
  virtual Pose LivePose() const = 0;
};

struct SerialFaults {
  bool silent = false;    // the meter answers nothing (not in remote mode, cable switch)
  int garbage_next = 0;   // the next N replies are replaced by garbage bytes
  int truncate_next = 0;  // the next N replies stop half-way
  // The injected quality code is a fault of the meter: the PR-650 endpoint applies it over the
  // backend's own code and counts quality_count down (one place only; the optics never do).
  // The meter's own code: the PR-650's quality code (0–99), the PR-670's result code (−8, −1,
  // −10, ...), the CS-2000's ERxx number (10 → ER10).
  int quality_code = 0;       // force this quality code ...
  int quality_count = 0;      // ... for the next N measurements
  double vanish_seconds = 0;  // >0: the port vanishes during the next D5 transfer, back after this
  int no_data_next = 0;       // the next N measurements give no data: their reports answer "-1"
  int units_code = 0;         // the reports' units code: 0 radiance, 1 irradiance, 2 uncalibrated
  // The meter leaves remote mode at the next command (its operator pressed a key, or it fell back
  // to local mode) and ignores it; it answers again once a driver re-enters remote mode (PHOTO,
  // RMTS,1). Consumed when it fires. The PR-650 has no such way back (only a power cycle).
  bool leave_remote = false;
};

struct ModbusFaults {
  int exception_code = 0;   // reply with this exception (2 or 6) ...
  int exception_count = 0;  // ... to the next N requests
  int late_reply_ms = 0;    // delay the next N replies by this much (real ms) ...
  int late_count = 0;
  bool drop_connection = false;  // close the TCP connection at the next request
  bool alarm_mid_move = false;   // the next move raises an alarm half-way
  bool stall = false;            // the next move never clears MOVE
  // A persistent setting, not a "next N" fault: the drives lay 32-bit values in the other word
  // order than configured (as if someone changed the drives' word-order parameter).
  bool swap_word_order = false;
  // >0: at the next axis request the drives go away for this many real ms: that TCP connection
  // closes and the listener closes too (new connections are refused), every axis request
  // meanwhile is dropped (RTU: left unanswered); then the endpoint listens on the same port again.
  int outage_ms = 0;
};

// Mutable shared state, thread-safe. Set from flags at start-up and at runtime through the
// control unit id of the Modbus endpoint.
class SimControl {
 public:
  MountedTarget mounted() const {
    std::lock_guard l(mu_);
    return mounted_;
  }
  void set_mounted(MountedTarget t) {
    std::lock_guard l(mu_);
    mounted_ = t;
  }
  SerialFaults serial() const {
    std::lock_guard l(mu_);
    return serial_;
  }
  void set_serial(const SerialFaults& f) {
    std::lock_guard l(mu_);
    serial_ = f;
  }
  ModbusFaults modbus() const {
    std::lock_guard l(mu_);
    return modbus_;
  }
  void set_modbus(const ModbusFaults& f) {
    std::lock_guard l(mu_);
    modbus_ = f;
  }
  // The sample-fixed method: lamp and detector placed by hand at `placed()`, the holder's pose
  // ignored by the optics while by_hand() (the control unit's registers 29–33).
  bool by_hand() const {
    std::lock_guard l(mu_);
    return by_hand_;
  }
  Directions placed() const {
    std::lock_guard l(mu_);
    return placed_;
  }
  void set_placed(bool by_hand, const Directions& d) {
    std::lock_guard l(mu_);
    by_hand_ = by_hand;
    placed_ = d;
  }
  // Atomically applies `fn` to the faults (to count down "next N" faults).
  template <typename Fn>
  auto UpdateSerial(Fn fn) {
    std::lock_guard l(mu_);
    return fn(serial_);
  }
  template <typename Fn>
  auto UpdateModbus(Fn fn) {
    std::lock_guard l(mu_);
    return fn(modbus_);
  }

 private:
  mutable std::mutex mu_;
  MountedTarget mounted_ = MountedTarget::kSample;
  SerialFaults serial_;
  ModbusFaults modbus_;
  bool by_hand_ = false;
  Directions placed_;
};

}  // namespace brdf::sim
