// brdf-sim: a whole simulated rig in one process. A meter on a pty (--meter: the PR-650, a
// PR-655/670 or a CS-2000/2000A/3000) and the rotation stage on Modbus TCP (and RTU on a pty with
// --rtu), joined by the optical model, so the daemon and the tests can run plans without
// hardware. `brdf-sim truth` prints the virtual sample's true BRDF.
//
// stdout carries only the start-up contract (tools/brdf-sim/README.md), one line each, flushed:
//   <meter> <port path>          (pr650, pr655, pr670, cs2000, cs2000a or cs3000: --meter)
//   modbus-tcp <host>:<port>
//   modbus-rtu <pty path>        (with --rtu only)
//   control-unit <unit id>
//   ready
// Everything else (logs) goes to stderr. SIGTERM or SIGINT stops it cleanly with exit code 0.
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "daemon/config/startup.h"
#include "tools/brdf-sim/meter/cs2000_endpoint.h"
#include "tools/brdf-sim/meter/pr650_endpoint.h"
#include "tools/brdf-sim/meter/pr670_endpoint.h"
#include "tools/brdf-sim/optics/manual_detector.h"
#include "tools/brdf-sim/optics/material.h"
#include "tools/brdf-sim/optics/optics.h"
#include "tools/brdf-sim/optics/truth.h"
#include "tools/brdf-sim/sim_config.h"
#include "tools/brdf-sim/sim_shared.h"
#include "tools/brdf-sim/stage/simulator.h"

namespace brdf::sim {
namespace {

constexpr int kUsageError = 2;
constexpr int kStartError = 1;

StageSimConfig StageConfigFrom(const SimConfig& c) {
  StageSimConfig s;
  s.time_scale = TimeScale{c.time_scale};
  s.tcp_host = c.modbus_host;
  s.tcp_port = c.modbus_port;
  s.serve_tcp = true;
  s.serve_rtu = c.rtu;
  for (std::size_t i = 0; i < s.axes.size(); ++i) {
    s.axes[i].min_deg = c.axes[i].min_deg;
    s.axes[i].max_deg = c.axes[i].max_deg;
    s.axes[i].home_speed_deg_s = c.axes[i].home_speed_deg_s;
    s.axes[i].word_order = StageWordOrder(c);
    s.axes[i].ramp_unit = StageRampUnit(c);
  }
  s.drive_function_codes = StageFunctionCodes(c);
  s.axes[kDeltaAxis].present = c.detector_arm;
  return s;
}

Pr650EndpointOptions MeterOptionsFrom(const SimConfig& c) {
  Pr650EndpointOptions o;
  o.time_scale = TimeScale{c.time_scale};
  o.wake_window_s = c.wake_window_s;
  o.pace_replies = c.pacing;
  o.fifo_bytes = c.fifo_bytes;
  o.link_path = c.pr650_link;
  o.quirks.d5_header_bare_cr = c.d5_header_bare_cr;
  o.m0_reply_is_quality = c.m0_reply_is_quality;
  return o;
}

LineEndpointOptions LineOptionsFrom(const SimConfig& c, const std::string& default_serial) {
  LineEndpointOptions o;
  o.time_scale = TimeScale{c.time_scale};
  o.link_path = c.pr650_link;
  o.serial_number = c.meter_serial.empty() ? default_serial : c.meter_serial;
  return o;
}

// The meter --meter names, over the optics.
std::unique_ptr<MeterPort> MakeMeter(const SimConfig& c, MeterBackend& optics,
                                     SimControl& control) {
  const std::string family = MeterFamilyOf(c.meter);
  if (family == "pr670") {
    Pr670EndpointOptions o{LineOptionsFrom(c, "67012345"), MeterModelOf(c.meter)};
    o.line.eol = "\r\n";
    return std::make_unique<Pr670Endpoint>(optics, control, std::move(o));
  }
  if (family == "cs2000") {
    Cs2000EndpointOptions o{LineOptionsFrom(c, "20001234"), MeterModelOf(c.meter)};
    o.line.eol = "\n";
    return std::make_unique<Cs2000Endpoint>(optics, control, std::move(o));
  }
  Pr650EndpointOptions o = MeterOptionsFrom(c);
  if (!c.meter_serial.empty()) o.serial_number = c.meter_serial;
  return std::make_unique<Pr650Endpoint>(optics, control, std::move(o));
}

// The optics on the meter's grid.
OpticsConfig OpticsFor(const SimConfig& c) {
  OpticsConfig o = c.optics;
  const std::string family = MeterFamilyOf(c.meter);
  if (family == "pr670") o.grid = Pr670Grid(MeterModelOf(c.meter));
  if (family == "cs2000") o.grid = WavelengthGrid{380, 1, 401};
  return o;
}

// One start-up line on stdout, flushed at once: a test may be waiting for it.
void Announce(const std::string& line) {
  std::fputs((line + "\n").c_str(), stdout);
  std::fflush(stdout);
}

int Run(const SimConfig& config, const sigset_t& stop_signals) {
  SimControl control;
  control.set_mounted(config.mounted);
  control.set_serial(config.serial_faults);
  control.set_modbus(config.modbus_faults);

  // The control unit's power-cycle register reaches the meter through this pointer, set once the
  // meter exists and before either endpoint starts serving.
  MeterPort* meter_ptr = nullptr;
  StageSimulator stage(StageConfigFrom(config), control, [&meter_ptr] {
    if (meter_ptr != nullptr) {
      spdlog::info("control unit: power-cycling the meter");
      meter_ptr->PowerCycle();
    }
  });
  // Without a detector arm the stage has no δ: the detector stays where the operator put it.
  ManualDetectorPose manual_detector(stage, config.manual_delta_deg);
  const StagePoseSource& live_pose =
      config.detector_arm ? static_cast<const StagePoseSource&>(stage) : manual_detector;
  RigOptics optics(live_pose, control, OpticsFor(config));
  const std::unique_ptr<MeterPort> meter_port = MakeMeter(config, optics, control);
  MeterPort& meter = *meter_port;
  meter_ptr = &meter;

  if (Status s = meter.Start(); !s.ok()) {
    spdlog::error("cannot start the simulated {}: {}", MeterModelOf(config.meter), s.ToString());
    return kStartError;
  }
  std::string error;
  if (!stage.Start(&error)) {
    spdlog::error(
        "cannot start the simulated stage on {}:{}: {}; pick another --modbus-port "
        "(0 = any free port)",
        config.modbus_host, config.modbus_port, error);
    meter.Stop();
    return kStartError;
  }
  spdlog::info(
      "{} on {} (pty {}), Modbus TCP on {}:{}{}{}, time scale {}, seed {}, {} sample, "
      "{} mounted",
      MeterModelOf(config.meter), meter.path(), meter.slave_path(), config.modbus_host,
      stage.tcp_port(), config.rtu ? ", Modbus RTU on " : "", config.rtu ? stage.rtu_path() : "",
      config.time_scale, config.optics.seed, optics.sample().name(),
      MountedTargetName(config.mounted));

  Announce(config.meter + " " + meter.path());
  Announce("modbus-tcp " + config.modbus_host + ":" + std::to_string(stage.tcp_port()));
  if (config.rtu) Announce("modbus-rtu " + stage.rtu_path());
  Announce("control-unit " + std::to_string(stage.control_unit_id()));
  Announce("ready");

  int signal_number = 0;
  while (sigwait(&stop_signals, &signal_number) != 0) {
  }
  spdlog::info("signal {} received: stopping", signal_number);
  // The stage first: its control unit is what could still power-cycle the meter.
  stage.Shutdown();
  meter.Stop();
  return 0;
}

void SetUpLogging(const std::string& level) {
  auto logger = spdlog::stderr_color_mt("brdf-sim");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(level));
}

}  // namespace
}  // namespace brdf::sim

int main(int argc, char** argv) {
  using namespace brdf::sim;

  // Block the stop signals before any thread starts, so every thread inherits the mask and the
  // main thread alone receives them in sigwait. Writes to a closed socket or pty must fail with
  // EPIPE, not kill the process.
  const sigset_t stop_signals = brdf::daemon::BlockStopSignals();

  SimConfig config;
  TruthQuery truth;
  CLI::App app(
      "brdf-sim: a simulated spectral BRDF rig (a spectroradiometer on a pty, rotation stage on "
      "Modbus)");
  AddRunFlags(app, config);
  CLI::App* truth_cmd = app.add_subcommand(
      "truth", "Print the virtual sample's true BRDF (sr^-1), 380-780 nm / 4 nm");
  AddTruthFlags(*truth_cmd, truth);
  app.require_subcommand(0, 1);

  // The file first, so that flags override it.
  if (auto path = FindConfigPath(argc, argv)) {
    if (brdf::Status s = LoadConfigFile(*path, config); !s.ok()) {
      std::fprintf(stderr, "brdf-sim: %s\n", s.ToString().c_str());
      return kUsageError;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  if (*truth_cmd) {
    brdf::Result<brdf::material::Material> sample = TruthSample(truth, config.optics);
    if (!sample.ok()) {
      std::fprintf(stderr, "brdf-sim: %s\n", sample.status().ToString().c_str());
      return kUsageError;
    }
    // On the meter's grid (--meter before `truth`): what a session on that meter holds.
    std::fputs(FormatTruth(truth, *sample, OpticsFor(config).grid).c_str(), stdout);
    return 0;
  }

  FinishFlags(app, config);
  brdf::Status valid = ValidateConfig(config);
  if (valid.ok()) valid = LoadMountedMaterial(config.optics);
  if (brdf::Status s = valid; !s.ok()) {
    std::fprintf(stderr, "brdf-sim: %s\n", s.ToString().c_str());
    return kUsageError;
  }
  SetUpLogging(config.log_level);
  return Run(config, stop_signals);
}
