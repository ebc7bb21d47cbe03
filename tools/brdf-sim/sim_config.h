// brdf-sim's configuration: built-in defaults, then a TOML file (--config), then command-line
// flags, each overriding the one before. README.md lists every flag and key.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/status.h"
#include "tools/brdf-sim/optics/optics.h"
#include "tools/brdf-sim/sim_shared.h"
#include "tools/brdf-sim/stage/pdu.h"
#include "tools/brdf-sim/stage/sim_axis.h"

namespace CLI {
class App;
}

namespace brdf::sim {

// One axis of the simulated stage: how far it may turn, and how fast it homes. A move runs at the
// speed the driver writes into the drive's operation data, as on a real AZ drive.
struct AxisSettings {
  double home_speed_deg_s = 20;
  double min_deg = 0;
  double max_deg = 0;
};

// Axis order in SimConfig::axes (the Modbus unit id is index + 1).
enum AxisIndex : int { kAlphaAxis = 0, kBetaAxis = 1, kGammaAxis = 2, kDeltaAxis = 3 };
inline constexpr std::array<const char*, 4> kAxisNames = {"alpha", "beta", "gamma", "delta"};

struct SimConfig {
  std::string config_path;  // the --config file read, if any (for the log)
  double time_scale = 1.0;  // simulated time runs this many times faster than real time

  // The meter on the pty: "pr650" (default), "pr670" or "pr655" (PR-670 protocol), "cs2000",
  // "cs2000a" or "cs3000" (CS-2000 protocol). [meter] model in the file, --meter on the line.
  std::string meter = "pr650";
  std::string meter_serial;  // what the meter reports as its serial number (empty: the model's)

  std::string modbus_host = "127.0.0.1";
  int modbus_port = 0;          // 0 = an ephemeral port, printed at start-up
  bool rtu = false;             // also serve Modbus RTU on a pty
  bool detector_arm = true;     // δ is a motorized axis (unit 4); false: the operator moves it
  double manual_delta_deg = 0;  // without the arm: where the operator put the detector (δ)
  bool pacing = true;           // pace PR-650 replies at 9600 baud
  int fifo_bytes = 14;          // ... handed to the computer in bursts of this many (1: per byte)
  double wake_window_s = 5;     // the PR-650 enters remote mode only within this long of power-on
                                // (simulated seconds; 0 = any time)
  std::string pr650_link;       // where the PR-650 port link goes (empty: a private temp dir)
  bool d5_header_bare_cr = false;    // D5's "qq,U" ended by a bare CR (a quoted manual's variant)
  bool m0_reply_is_quality = false;  // M0 answers the quality code, not the meter's 000

  // The axis drives, set as on an AZ drive: which function codes they answer (a profile name,
  // "az", "leadshine", "moons", or a list "3,6,8,16"), and how a 32-bit value lies over two
  // registers ("upper_first", the AZ default, or "lower_first"), and the unit of the ramp rates
  // in the operation block ("khz_per_s", the AZ default, "s" or "ms_per_khz").
  std::string stage_function_codes = "az";
  std::string stage_word_order = "upper_first";
  std::string stage_ramp_unit = "khz_per_s";

  std::array<AxisSettings, 4> axes = {{
      // home speed, min, max
      {20, 0, 90},      // α tilt
      {20, -180, 180},  // β rotation about the vertical
      {20, -180, 180},  // γ dial about the normal
      {20, 0, 180},     // δ detector arm
  }};

  MountedTarget mounted = MountedTarget::kSample;
  SerialFaults serial_faults;
  ModbusFaults modbus_faults;

  // Lamp, detector, white standard, ambient level, noise, the rig's known errors; also --seed
  // (optics.seed), --anisotropic, --glossy and --material (the sample), which only the optics
  // use.
  OpticsConfig optics;

  std::string log_level = "info";  // trace, debug, info, warn, error, off
};

// `brdf-sim truth`: the true BRDF at one direction.
struct TruthQuery {
  Directions directions;
  bool anisotropic = false;
  bool glossy = false;
  std::string material_path;  // --material: the sample in a material file
  bool json = false;
};

// The meter keys --meter and [meter] model take.
inline constexpr std::array<const char*, 6> kMeterKeys = {"pr650",  "pr655",   "pr670",
                                                          "cs2000", "cs2000a", "cs3000"};
// The meter's own name for a key ("pr670" → "PR-670"), its wavelength grid, and its protocol
// family ("pr650", "pr670" or "cs2000").
std::string MeterModelOf(const std::string& key);
std::string MeterFamilyOf(const std::string& key);

// Names of mounted targets as flags and the control unit spell them: sample, white, dark.
const char* MountedTargetName(MountedTarget target);
std::optional<MountedTarget> ParseMountedTarget(const std::string& name);

// The value of --config in argv (both "--config PATH" and "--config=PATH"), if any. Read before
// the flags so that the flags can override the file.
std::optional<std::string> FindConfigPath(int argc, const char* const* argv);

// Reads a TOML file over `config`. Unknown keys are errors (a typo must not go unnoticed). The
// message names the file, the key and what is expected. A relative `material` path in the file
// is taken relative to the file's directory.
Status LoadConfigFile(const std::string& path, SimConfig& config);
Status LoadConfigString(const std::string& toml_text, const std::string& source_name,
                        SimConfig& config);

// Registers the run flags on `app`, bound to `config` (a flag that is not given leaves the field).
// Call FinishFlags after parsing.
void AddRunFlags(CLI::App& app, SimConfig& config);
// Applies what the flags imply (a fault code without a count means "the next one").
void FinishFlags(CLI::App& app, SimConfig& config);

// Registers `truth`'s flags on its subcommand, bound to `query`.
void AddTruthFlags(CLI::App& truth, TruthQuery& query);

// The drives' settings as the stage simulator takes them (ValidateConfig has checked them).
FunctionCodes StageFunctionCodes(const SimConfig& config);
SimWordOrder StageWordOrder(const SimConfig& config);
SimRampUnit StageRampUnit(const SimConfig& config);

// Checks ranges: time scale > 0, port 0–65535, speeds > 0, min < max, and so on.
Status ValidateConfig(const SimConfig& config);

}  // namespace brdf::sim
