// What the PR-670 and CS-2000 driver tests stand on: a light source whose spectrum is known
// exactly on any grid, brdf-sim's own meter endpoints on real pseudo-terminals (in this process),
// driver options shrunk so each test runs in milliseconds, and the fixture both use.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/wavelength_grid.h"
#include "drivers/cs2000/options.h"
#include "drivers/line_meter/options.h"
#include "drivers/pr670/options.h"
#include "drivers/spectroradiometer.h"
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

// Driver options for a pty: short waits (and the PR-670's typing pace of 1 ms).
inline void ShrinkLineMeterOptions(drivers::LineMeterOptions& o, const std::string& port,
                                   std::vector<std::string>* log) {
  using std::chrono::milliseconds;
  o.port = port;
  o.command_pacing = milliseconds(2);
  o.quiet_gap = milliseconds(15);
  o.stall_timeout = milliseconds(300);
  o.reply_timeout = milliseconds(500);
  o.measurement_timeout = milliseconds(1500);
  o.log = [log](std::string_view m) { log->emplace_back(m); };
}

inline drivers::Pr670Options FastPr670(const std::string& port, std::vector<std::string>* log) {
  using std::chrono::milliseconds;
  drivers::Pr670Options o;
  ShrinkLineMeterOptions(o, port, log);
  o.char_gap = milliseconds(1);
  o.quit_settle = milliseconds(10);
  o.remote_timeout = milliseconds(500);
  o.adaptive_exposure_max = milliseconds(500);
  return o;
}

inline drivers::Cs2000Options FastCs2000(const std::string& port, std::vector<std::string>* log) {
  drivers::Cs2000Options o;
  ShrinkLineMeterOptions(o, port, log);
  o.measure_start_timeout = std::chrono::milliseconds(1000);
  return o;
}

// A driver test's fixture: `Endpoint` (brdf-sim's meter) on a pty, lit by a GridBackend on its
// grid, and the `Meter` driver on its port with the fast options; the log the driver wrote.
template <typename Endpoint, typename Meter>
class MeterDriverTest : public ::testing::Test {
 protected:
  explicit MeterDriverTest(WavelengthGrid grid) : backend_{grid} {}

  // Starts the endpoint with `options`, then builds the driver with `make_options(port, log)`.
  template <typename EndpointOptions, typename MeterOptions>
  void Start(const EndpointOptions& options,
             MeterOptions (*make_options)(const std::string&, std::vector<std::string>*)) {
    endpoint_ = std::make_unique<Endpoint>(backend_, control_, options);
    ASSERT_TRUE(endpoint_->Start().ok());
    meter_ = std::make_unique<Meter>(make_options(endpoint_->path(), &log_));
  }
  void TearDown() override {
    meter_.reset();
    endpoint_->Stop();
  }
  void ConnectAndConfigure(drivers::MeasurementSettings settings) {
    Status connected = meter_->Connect(Ctx());
    ASSERT_TRUE(connected.ok()) << connected.ToString();
    Status configured = meter_->Configure(settings, Ctx());
    ASSERT_TRUE(configured.ok()) << configured.ToString();
  }
  void Fault(std::function<void(sim::SerialFaults&)> set) { control_.UpdateSerial(set); }

  GridBackend backend_;
  sim::SimControl control_;
  std::unique_ptr<Endpoint> endpoint_;
  std::vector<std::string> log_;
  std::unique_ptr<Meter> meter_;
};

// Whether `commands` holds `command`.
inline bool Sent(const std::vector<std::string>& commands, const std::string& command) {
  for (const std::string& c : commands) {
    if (c == command) return true;
  }
  return false;
}

}  // namespace brdf::testing
