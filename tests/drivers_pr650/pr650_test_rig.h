// What the PR-650 driver tests stand on: a fake optical backend for the simulated meter (the
// device mock), the simulator's Pr650Endpoint on a real pty, and driver options shrunk so each
// test runs in milliseconds.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drivers/pr650/options.h"
#include "drivers/pr650/spectroradiometer.h"
#include "tools/brdf-sim/meter/pr650_endpoint.h"
#include "tools/brdf-sim/sim_shared.h"

namespace brdf::testing {

// A light source whose spectrum is known exactly: radiance_i = level * (1 + i / 50), so every band
// differs and a misplaced band shows.
class FakeMeterBackend final : public sim::MeterBackend {
 public:
  sim::SimMeasurement Measure(const sim::MeterSetup& setup) override {
    std::lock_guard lock(mu_);
    setups_.push_back(setup);
    sim::SimMeasurement m;
    m.integration_ms = setup.integration_ms == 0 ? 250 : setup.integration_ms;
    if (!durations_s_.empty()) {
      m.duration_s = durations_s_.front();
      durations_s_.pop_front();
    } else {
      m.duration_s = default_duration_s_;
    }
    m.quality_code = quality_code_;
    m.radiance = Spectrum(level_);
    m.integrated = 0;
    for (double v : m.radiance) m.integrated += 4 * v;
    return m;
  }

  static std::vector<double> Spectrum(double level) {
    std::vector<double> r(101);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = level * (1 + static_cast<double>(i) / 50);
    return r;
  }

  void set_level(double level) {
    std::lock_guard lock(mu_);
    level_ = level;
  }
  double level() const {
    std::lock_guard lock(mu_);
    return level_;
  }
  // Simulated seconds each measurement takes: the queued ones first, then the default.
  void queue_durations(std::vector<double> seconds) {
    std::lock_guard lock(mu_);
    durations_s_.assign(seconds.begin(), seconds.end());
  }
  void set_default_duration(double seconds) {
    std::lock_guard lock(mu_);
    default_duration_s_ = seconds;
  }
  // The quality the optics report (before any injected fault).
  void set_quality(int code) {
    std::lock_guard lock(mu_);
    quality_code_ = code;
  }
  std::vector<sim::MeterSetup> setups() const {
    std::lock_guard lock(mu_);
    return setups_;
  }

 private:
  mutable std::mutex mu_;
  double level_ = 0.0123;
  double default_duration_s_ = 0.3;
  std::deque<double> durations_s_;
  int quality_code_ = 0;
  std::vector<sim::MeterSetup> setups_;
};

// Simulated time runs 10× faster than real time in these tests: the 5 s wake-up window is 0.5 s,
// a 1.8 s D5 transfer 0.18 s.
//
// M0 answers with the quality code (brdf-sim's older reply, m0_reply_is_quality): the driver's
// Measure still judges the quality from M0's reply, and these tests drive that path. The meter's
// own "000" reply is tested in pr650_endpoint_test.cc and pr650_reports_test.cc.
inline sim::Pr650EndpointOptions FastEndpointOptions() {
  sim::Pr650EndpointOptions o;
  o.time_scale.factor = 10;
  o.pace_replies = true;
  o.m0_reply_is_quality = true;
  return o;
}

// Collects the driver's log lines.
class LogCapture {
 public:
  drivers::serial::LogSink sink() {
    return [this](std::string_view line) {
      std::lock_guard lock(mu_);
      lines_.emplace_back(line);
    };
  }
  bool Contains(std::string_view text) const {
    std::lock_guard lock(mu_);
    for (const auto& l : lines_) {
      if (l.find(text) != std::string::npos) return true;
    }
    return false;
  }
  std::string All() const {
    std::lock_guard lock(mu_);
    std::string out;
    for (const auto& l : lines_) out += l + "\n";
    return out;
  }

 private:
  mutable std::mutex mu_;
  std::vector<std::string> lines_;
};

inline drivers::Pr650Options FastDriverOptions(const std::string& port, LogCapture& log) {
  using namespace std::chrono_literals;
  drivers::Pr650Options o;
  o.port = port;
  o.command_pacing = 5ms;
  o.quiet_gap = 20ms;
  o.stall_timeout = 300ms;
  o.reply_timeout = 400ms;
  o.measurement_timeout = 3000ms;
  o.rts_drop = 5ms;
  o.wake_settle = 10ms;
  o.wake_attempts = 3;
  o.log = log.sink();
  return o;
}

inline CallContext Ctx(std::chrono::milliseconds timeout = std::chrono::seconds(10),
                       CancelToken cancel = CancelToken()) {
  return CallContext::WithTimeout(timeout, std::move(cancel));
}

// Counts how often `command` appears in the endpoint's command log.
inline int CountCommand(const sim::Pr650Endpoint& endpoint, const std::string& command) {
  int n = 0;
  for (const auto& c : endpoint.commands()) n += c == command ? 1 : 0;
  return n;
}

// A simulated meter on a pty (FakeMeterBackend optics, the sim's fault control) and the options for
// a driver talking to it.
class Pr650DriverTest : public ::testing::Test {
 protected:
  void SetUp() override { StartEndpoint(FastEndpointOptions()); }

  void StartEndpoint(const sim::Pr650EndpointOptions& options) {
    endpoint_.reset();
    endpoint_ = std::make_unique<sim::Pr650Endpoint>(backend_, control_, options);
    ASSERT_TRUE(endpoint_->Start().ok());
    options_ = FastDriverOptions(endpoint_->path(), log_);
  }

  std::unique_ptr<drivers::Pr650Spectroradiometer> Driver() {
    return std::make_unique<drivers::Pr650Spectroradiometer>(options_);
  }

  // A connected driver with a fixed integration time.
  std::unique_ptr<drivers::Pr650Spectroradiometer> Configured(int integration_ms) {
    auto meter = Driver();
    Status s = meter->Connect(Ctx());
    EXPECT_TRUE(s.ok()) << s.ToString();
    s = meter->Configure({integration_ms, 1, false}, Ctx());
    EXPECT_TRUE(s.ok()) << s.ToString();
    return meter;
  }

  void InjectQuality(int code, int count) {
    control_.UpdateSerial([&](sim::SerialFaults& f) {
      f.quality_code = code;
      f.quality_count = count;
      return 0;
    });
  }

  std::vector<int> MeasuredIntegrations() const {
    std::vector<int> out;
    for (const auto& s : backend_.setups()) out.push_back(s.integration_ms);
    return out;
  }

  FakeMeterBackend backend_;
  sim::SimControl control_;
  std::unique_ptr<sim::Pr650Endpoint> endpoint_;
  LogCapture log_;
  drivers::Pr650Options options_;
};

// `report` holds FakeMeterBackend::Spectrum(level), to the meter's 4 printed digits.
inline void ExpectSpectrumOf(const drivers::SpectrumReport& report, double level) {
  const std::vector<double> want = FakeMeterBackend::Spectrum(level);
  ASSERT_EQ(report.radiance.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    // The meter prints 4 significant digits.
    EXPECT_NEAR(report.radiance[i], want[i], want[i] * 6e-4) << "band " << i;
  }
  double integrated = 0;
  for (double v : want) integrated += 4 * v;
  EXPECT_NEAR(report.integrated, integrated, integrated * 6e-4);
}

}  // namespace brdf::testing
