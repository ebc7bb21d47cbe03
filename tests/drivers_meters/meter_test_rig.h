// What the PR-670 and CS-2000 driver tests stand on: a light source whose spectrum is known
// exactly on any grid, brdf-sim's own meter endpoints on real pseudo-terminals (in this process),
// and driver options shrunk so each test runs in milliseconds.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/wavelength_grid.h"
#include "drivers/cs2000/options.h"
#include "drivers/pr670/options.h"
#include "tools/brdf-sim/meter/cs2000_endpoint.h"
#include "tools/brdf-sim/meter/pr670_endpoint.h"
#include "tools/brdf-sim/sim_shared.h"

namespace brdf::testing {

// radiance_i = level · (1 + i / 100) on `grid`: every band differs, so a misplaced one shows. The
// light level's quality (0, 10 weak, 18 low, 19 overload) is set by the test.
class GridBackend final : public sim::MeterBackend {
 public:
  explicit GridBackend(WavelengthGrid grid) : grid_(grid) {}

  sim::SimMeasurement Measure(const sim::MeterSetup& setup) override {
    std::lock_guard lock(mu_);
    setups_.push_back(setup);
    sim::SimMeasurement m;
    m.integration_ms = setup.integration_ms == 0 ? 250 : setup.integration_ms;
    m.duration_s = 0.01;
    m.quality_code = qualities_.empty() ? quality_ : qualities_.front();
    if (!qualities_.empty()) qualities_.erase(qualities_.begin());
    m.radiance = Spectrum(grid_, level_);
    for (double v : m.radiance) m.integrated += v * grid_.step_nm;
    return m;
  }

  static std::vector<double> Spectrum(const WavelengthGrid& grid, double level) {
    std::vector<double> r(grid.count);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = level * (1 + static_cast<double>(i) / 100);
    return r;
  }

  // The quality every measurement earns, after the queued ones.
  void set_quality(int code) {
    std::lock_guard lock(mu_);
    quality_ = code;
  }
  void queue_qualities(std::vector<int> codes) {
    std::lock_guard lock(mu_);
    qualities_ = std::move(codes);
  }
  double level() const { return level_; }

 private:
  const WavelengthGrid grid_;
  mutable std::mutex mu_;
  double level_ = 0.0125;
  int quality_ = 0;
  std::vector<int> qualities_;
  std::vector<sim::MeterSetup> setups_;
};

inline CallContext Ctx(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  return CallContext::WithTimeout(timeout);
}

// The simulated meters: fast simulated time, replies as fast as the pty takes them.
inline sim::LineEndpointOptions FastLine(const std::string& eol, const std::string& serial) {
  sim::LineEndpointOptions o;
  o.time_scale = sim::TimeScale{100};
  o.eol = eol;
  o.serial_number = serial;
  return o;
}

// Driver options for a pty: short waits, a typing pace of 1 ms.
inline drivers::Pr670Options FastPr670(const std::string& port, std::vector<std::string>* log) {
  using std::chrono::milliseconds;
  drivers::Pr670Options o;
  o.port = port;
  o.char_gap = milliseconds(1);
  o.command_pacing = milliseconds(2);
  o.quiet_gap = milliseconds(15);
  o.stall_timeout = milliseconds(300);
  o.reply_timeout = milliseconds(500);
  o.quit_settle = milliseconds(10);
  o.remote_timeout = milliseconds(500);
  o.measurement_timeout = milliseconds(1500);
  o.adaptive_exposure_max = milliseconds(500);
  o.log = [log](std::string_view m) { log->emplace_back(m); };
  return o;
}

inline drivers::Cs2000Options FastCs2000(const std::string& port, std::vector<std::string>* log) {
  using std::chrono::milliseconds;
  drivers::Cs2000Options o;
  o.port = port;
  o.command_pacing = milliseconds(2);
  o.quiet_gap = milliseconds(15);
  o.stall_timeout = milliseconds(300);
  o.reply_timeout = milliseconds(500);
  o.measure_start_timeout = milliseconds(1000);
  o.measurement_timeout = milliseconds(1500);
  o.log = [log](std::string_view m) { log->emplace_back(m); };
  return o;
}

// Whether `commands` holds `command`.
inline bool Sent(const std::vector<std::string>& commands, const std::string& command) {
  for (const std::string& c : commands) {
    if (c == command) return true;
  }
  return false;
}

}  // namespace brdf::testing
