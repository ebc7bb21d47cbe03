#include "tools/brdf-sim/sim_config.h"

#include <toml++/toml.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include "core/toml/table_reader.h"
#include "tools/brdf-sim/optics/errors_settings.h"

namespace brdf::sim {
namespace {

// ---- TOML reading (core/toml/table_reader.h): every key is checked, every problem names the
// file, the line and the key. ----

using toml_keys::Empty;
using toml_keys::TableReader;

// One key into a field of the file's types; a string may be empty, a number any finite one,
// and ValidateConfig checks the ranges afterwards as for the flags.
void Get(TableReader& t, std::string_view key, double& out) {
  t.Double(key, out);
}
void Get(TableReader& t, std::string_view key, int& out) {
  t.Int(key, out, INT32_MIN, INT32_MAX);
}
void Get(TableReader& t, std::string_view key, std::uint64_t& out) {
  t.Int(key, out, 0, INT64_MAX);
}
void Get(TableReader& t, std::string_view key, bool& out) {
  t.Bool(key, out);
}
void Get(TableReader& t, std::string_view key, std::string& out) {
  t.String(key, out, Empty::kAllowed);
}

// A fault code given without its count means "the next one".
void DefaultCount(int code, int& count) {
  if (code != 0 && count == 0) count = 1;
}

void ReadSerialFaults(TableReader& t, SerialFaults& f) {
  Get(t, "silent", f.silent);
  Get(t, "garbage_next", f.garbage_next);
  Get(t, "truncate_next", f.truncate_next);
  Get(t, "quality_code", f.quality_code);
  Get(t, "quality_count", f.quality_count);
  Get(t, "vanish_seconds", f.vanish_seconds);
  Get(t, "leave_remote", f.leave_remote);
  if (t.table() != nullptr && t.table()->get("quality_count") == nullptr) {
    DefaultCount(f.quality_code, f.quality_count);
  }
  t.Finish();
}

void ReadModbusFaults(TableReader& t, ModbusFaults& f) {
  Get(t, "exception_code", f.exception_code);
  Get(t, "exception_count", f.exception_count);
  Get(t, "late_reply_ms", f.late_reply_ms);
  Get(t, "late_count", f.late_count);
  Get(t, "drop_connection", f.drop_connection);
  Get(t, "alarm_mid_move", f.alarm_mid_move);
  Get(t, "stall", f.stall);
  if (t.table() != nullptr) {
    if (t.table()->get("exception_count") == nullptr) {
      DefaultCount(f.exception_code, f.exception_count);
    }
    if (t.table()->get("late_count") == nullptr) DefaultCount(f.late_reply_ms, f.late_count);
  }
  t.Finish();
}

void ReadFaults(TableReader& root, SimConfig& c) {
  TableReader faults = root.Sub("faults");
  TableReader serial = faults.Sub("serial");
  ReadSerialFaults(serial, c.serial_faults);
  TableReader modbus = faults.Sub("modbus");
  ReadModbusFaults(modbus, c.modbus_faults);
  faults.Finish();
}

void ReadDetector(TableReader& d, DetectorConfig& dc) {
  Get(d, "full_scale", dc.full_scale);
  Get(d, "adaptive_fill", dc.adaptive_fill);
  Get(d, "low_light_fill", dc.low_light_fill);
  Get(d, "weak_fill", dc.weak_fill);
  Get(d, "full_well_counts", dc.full_well_counts);
  Get(d, "read_noise_counts", dc.read_noise_counts);
  Get(d, "min_integration_ms", dc.min_integration_ms);
  Get(d, "max_integration_ms", dc.max_integration_ms);
  Get(d, "overhead_s", dc.overhead_s);
  d.Finish();
}

void ReadOptics(TableReader& root, OpticsConfig& c) {
  TableReader o = root.Sub("optics");
  Get(o, "white_reflectance", c.white_reflectance);
  Get(o, "ambient_radiance", c.ambient_radiance);
  Get(o, "noise_scale", c.noise_scale);
  TableReader lamp = o.Sub("lamp");
  Get(lamp, "color_temperature_k", c.lamp.color_temperature_k);
  Get(lamp, "irradiance_at_560nm", c.lamp.irradiance_at_560nm);
  lamp.Finish();
  TableReader detector = o.Sub("detector");
  ReadDetector(detector, c.detector);
  TableReader errors = o.Sub("errors");
  ReadErrorSources(errors, c.errors);
  o.Finish();
}

void ReadLinks(TableReader& root, SimConfig& c) {
  TableReader m = root.Sub("modbus");
  Get(m, "host", c.modbus_host);
  Get(m, "port", c.modbus_port);
  Get(m, "rtu", c.rtu);
  m.Finish();
  TableReader p = root.Sub("pr650");
  Get(p, "d5_header_bare_cr", c.d5_header_bare_cr);
  Get(p, "m0_reply_is_quality", c.m0_reply_is_quality);
  Get(p, "link", c.pr650_link);
  Get(p, "pacing", c.pacing);
  Get(p, "fifo_bytes", c.fifo_bytes);
  Get(p, "wake_window_s", c.wake_window_s);
  p.Finish();
}

void ReadMeter(TableReader& root, SimConfig& c) {
  TableReader m = root.Sub("meter");
  m.OneOf("model", c.meter, {"pr650", "pr655", "pr670", "cs2000", "cs2000a", "cs3000"});
  Get(m, "serial_number", c.meter_serial);
  m.Finish();
}

void ReadStage(TableReader& root, SimConfig& c) {
  TableReader s = root.Sub("stage");
  Get(s, "ramp_unit", c.stage_ramp_unit);
  Get(s, "function_codes", c.stage_function_codes);
  Get(s, "word_order", c.stage_word_order);
  Get(s, "detector_arm", c.detector_arm);
  Get(s, "manual_delta_deg", c.manual_delta_deg);
  for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
    TableReader a = s.Sub(kAxisNames[i]);
    Get(a, "home_speed_deg_s", c.axes[i].home_speed_deg_s);
    Get(a, "min_deg", c.axes[i].min_deg);
    Get(a, "max_deg", c.axes[i].max_deg);
    a.Finish();
  }
  s.Finish();
}

void ReadTable(TableReader& root, SimConfig& c) {
  Get(root, "time_scale", c.time_scale);
  Get(root, "seed", c.optics.seed);
  Get(root, "anisotropic", c.optics.anisotropic);
  Get(root, "glossy", c.optics.glossy);
  Get(root, "material", c.optics.material_path);
  Get(root, "log_level", c.log_level);
  std::string mounted;
  if (root.OneOf("mounted", mounted, {"sample", "white", "dark"})) {
    c.mounted = *ParseMountedTarget(mounted);
  }
  ReadLinks(root, c);
  ReadMeter(root, c);
  ReadStage(root, c);
  ReadFaults(root, c);
  ReadOptics(root, c.optics);
  root.Finish();
}

bool Finite(double x) {
  return std::isfinite(x);
}

}  // namespace

std::string MeterModelOf(const std::string& key) {
  if (key == "pr655") return "PR-655";
  if (key == "pr670") return "PR-670";
  if (key == "cs2000") return "CS-2000";
  if (key == "cs2000a") return "CS-2000A";
  if (key == "cs3000") return "CS-3000";
  return "PR-650";
}

std::string MeterFamilyOf(const std::string& key) {
  if (key == "pr655" || key == "pr670") return "pr670";
  if (key.rfind("cs", 0) == 0) return "cs2000";
  return "pr650";
}

const char* MountedTargetName(MountedTarget target) {
  switch (target) {
    case MountedTarget::kSample:
      return "sample";
    case MountedTarget::kWhite:
      return "white";
    case MountedTarget::kDark:
      return "dark";
  }
  return "unknown";
}

std::optional<MountedTarget> ParseMountedTarget(const std::string& name) {
  for (MountedTarget t : {MountedTarget::kSample, MountedTarget::kWhite, MountedTarget::kDark}) {
    if (name == MountedTargetName(t)) return t;
  }
  return std::nullopt;
}

std::optional<std::string> FindConfigPath(int argc, const char* const* argv) {
  constexpr std::string_view kFlag = "--config";
  std::optional<std::string> path;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") break;
    if (arg == kFlag && i + 1 < argc) {
      path = argv[++i];
    } else if (arg.size() > kFlag.size() + 1 && arg.substr(0, kFlag.size() + 1) == "--config=") {
      path = std::string(arg.substr(kFlag.size() + 1));
    }
  }
  return path;
}

Status LoadConfigString(const std::string& toml_text, const std::string& source_name,
                        SimConfig& config) {
  toml_keys::Problems problems(
      "brdf-sim config " + source_name, StatusCode::kInvalidArgument,
      "fix the file or drop --config (tools/brdf-sim/README.md lists every key)");
  BRDF_ASSIGN_OR_RETURN(const toml::table root, problems.Parse(toml_text, source_name));
  SimConfig updated = config;
  TableReader reader(problems, &root);
  ReadTable(reader, updated);
  BRDF_RETURN_IF_ERROR(problems.status());
  config = updated;
  return Status::Ok();
}

Status LoadConfigFile(const std::string& path, SimConfig& config) {
  std::ifstream in(path);
  if (!in) {
    return NotFound("brdf-sim config file '" + path +
                    "' cannot be opened; check the --config path and its permissions");
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::string material_before = config.optics.material_path;
  BRDF_RETURN_IF_ERROR(LoadConfigString(text.str(), path, config));
  // A material the file names is found relative to the file.
  std::string& material = config.optics.material_path;
  if (material != material_before && !material.empty() &&
      std::filesystem::path(material).is_relative()) {
    material = (std::filesystem::path(path).parent_path() / material).string();
  }
  return Status::Ok();
}

namespace {

// The meter on the pty and its link: model, serial, PR-650 pacing and wire variants.
void AddMeterFlags(CLI::App& app, SimConfig& c) {
  app.add_option("--meter", c.meter,
                 "The meter on the pty: pr650, pr670 (pr655), cs2000 (cs2000a, cs3000)")
      ->check(CLI::IsMember({"pr650", "pr655", "pr670", "cs2000", "cs2000a", "cs3000"}));
  app.add_option("--meter-serial", c.meter_serial, "The serial number the meter reports");
  app.add_flag("--pacing,!--no-pacing", c.pacing, "Pace PR-650 replies at 9600 baud");
  app.add_option("--fifo-bytes", c.fifo_bytes,
                 "With pacing: reply bytes reach the port in bursts of this many (a UART's "
                 "receive FIFO; 1: byte by byte)")
      ->check(CLI::Range(1, 4096));
  app.add_option("--wake-window", c.wake_window_s,
                 "Seconds after power-on within which the PR-650 accepts remote mode");
  app.add_option("--pr650-link", c.pr650_link,
                 "Path of the PR-650 port symlink (default: in a private temp directory)");
  app.add_flag("--pr650-bare-cr-header", c.d5_header_bare_cr,
               "End the D5 header line \"qq,U\" with a bare CR (a quoted manual's variant)");
  app.add_flag("--pr650-m0-quality", c.m0_reply_is_quality,
               "M0 answers the quality code (\"018\") instead of the meter's \"000\"");
}

// The stage's drives: register conventions, then each axis's homing speed and travel limits.
void AddStageFlags(CLI::App& app, SimConfig& c) {
  app.add_option("--stage-function-codes", c.stage_function_codes,
                 "Function codes the drives answer: az (3,6,8,16), leadshine, moons, or a list");
  app.add_option("--stage-word-order", c.stage_word_order,
                 "32-bit values in two registers: upper_first (AZ default) or lower_first");
  app.add_option("--stage-ramp-unit", c.stage_ramp_unit,
                 "Unit of the drives' ramp rates: khz_per_s (AZ default), s or ms_per_khz");
  for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
    const std::string n = kAxisNames[i];
    app.add_option("--" + n + "-home-speed", c.axes[i].home_speed_deg_s,
                   "Homing speed of " + n + ", deg/s (moves run at the speed the driver writes)");
    app.add_option("--" + n + "-min", c.axes[i].min_deg, "Lower travel limit of " + n + ", deg");
    app.add_option("--" + n + "-max", c.axes[i].max_deg, "Upper travel limit of " + n + ", deg");
  }
}

// What is mounted and how the meter sees it: the sample or a material file, noise and errors.
void AddSampleFlags(CLI::App& app, SimConfig& c) {
  app.add_flag("--anisotropic", c.optics.anisotropic, "Mount the brushed (anisotropic) sample");
  app.add_flag("--glossy", c.optics.glossy,
               "Mount the glossy isotropic sample (AnalyticBrdf::Glossy: the paint's base under a "
               "lobe of exponent 200)");
  const std::map<std::string, MountedTarget> targets = {{"sample", MountedTarget::kSample},
                                                        {"white", MountedTarget::kWhite},
                                                        {"dark", MountedTarget::kDark}};
  app.add_option("--mounted", c.mounted, "What is on the holder at start: sample, white or dark")
      ->transform(CLI::CheckedTransformer(targets, CLI::ignore_case));
  app.add_option("--material", c.optics.material_path,
                 "Mount the sample in this material file (docs/materials.md; deploy/materials/)");
  app.add_option("--noise-scale", c.optics.noise_scale, "Scale the meter's noise (0 = none)");
  app.add_option("--read-noise", c.optics.detector.read_noise_counts,
                 "The detector's read noise, counts (shot noise: full_well_counts at full scale)");
  AddErrorFlags(app, c.optics.errors);
}

// Faults to inject on the serial line and the Modbus link.
void AddFaultFlags(CLI::App& app, SimConfig& c) {
  SerialFaults& s = c.serial_faults;
  app.add_flag("--serial-silent", s.silent, "Fault: the PR-650 answers nothing");
  app.add_option("--serial-garbage-next", s.garbage_next, "Fault: next N replies are garbage");
  app.add_option("--serial-truncate-next", s.truncate_next, "Fault: next N replies stop half-way");
  app.add_option("--serial-quality-code", s.quality_code, "Fault: force this quality code ...");
  app.add_option("--serial-quality-count", s.quality_count,
                 "... for the next N measurements (default 1 when a code is given)");
  app.add_option("--serial-vanish-seconds", s.vanish_seconds,
                 "Fault: the pty vanishes during the next spectrum transfer, back after S seconds");
  app.add_flag("--serial-leave-remote", s.leave_remote,
               "Fault: the meter leaves remote mode at the next command (PR-670, CS-2000)");
  ModbusFaults& m = c.modbus_faults;
  app.add_option("--modbus-exception-code", m.exception_code,
                 "Fault: reply with this exception (2, 4 busy, 6) ...");
  app.add_option("--modbus-exception-count", m.exception_count,
                 "... to the next N requests (default 1 when a code is given)");
  app.add_option("--modbus-late-reply-ms", m.late_reply_ms,
                 "Fault: delay the next N replies by this many real ms ...");
  app.add_option("--modbus-late-count", m.late_count, "... N (default 1 when a delay is given)");
  app.add_flag("--modbus-drop-connection", m.drop_connection,
               "Fault: close the TCP connection at the next request");
  app.add_flag("--modbus-alarm-mid-move", m.alarm_mid_move,
               "Fault: the next move raises an alarm half-way");
  app.add_flag("--modbus-stall", m.stall, "Fault: the next move never clears MOVE");
}

}  // namespace

void AddRunFlags(CLI::App& app, SimConfig& c) {
  // Read beforehand (FindConfigPath); registered so that it is accepted and documented.
  app.add_option("--config", c.config_path, "TOML file with settings; flags override it");
  app.add_option("--time-scale", c.time_scale, "Simulated time runs this many times faster");
  app.add_option("--seed", c.optics.seed, "Noise seed (same seed, same readings)");
  app.add_option("--modbus-host", c.modbus_host, "Address the Modbus TCP server listens on");
  app.add_option("--modbus-port", c.modbus_port, "Modbus TCP port (0 = pick a free one)");
  app.add_flag("--rtu", c.rtu, "Also serve Modbus RTU on a pseudo-terminal");
  app.add_flag("!--no-detector-arm", c.detector_arm,
               "No motorized detector arm (no unit 4): the operator places the detector");
  app.add_option("--manual-delta", c.manual_delta_deg,
                 "Without the arm: the detector angle δ the operator set, deg");
  app.add_option("--log-level", c.log_level, "trace, debug, info, warn, error or off");
  AddMeterFlags(app, c);
  AddStageFlags(app, c);
  AddSampleFlags(app, c);
  AddFaultFlags(app, c);
}

void FinishFlags(CLI::App& app, SimConfig& c) {
  if (app.count("--serial-quality-code") > 0 && app.count("--serial-quality-count") == 0) {
    DefaultCount(c.serial_faults.quality_code, c.serial_faults.quality_count);
  }
  if (app.count("--modbus-exception-code") > 0 && app.count("--modbus-exception-count") == 0) {
    DefaultCount(c.modbus_faults.exception_code, c.modbus_faults.exception_count);
  }
  if (app.count("--modbus-late-reply-ms") > 0 && app.count("--modbus-late-count") == 0) {
    DefaultCount(c.modbus_faults.late_reply_ms, c.modbus_faults.late_count);
  }
}

void AddTruthFlags(CLI::App& truth, TruthQuery& q) {
  truth.add_option("--theta-i", q.directions.theta_i, "Incident polar angle, deg")->required();
  truth.add_option("--theta-o", q.directions.theta_o, "Outgoing polar angle, deg")->required();
  auto* phi = truth.add_option("--phi", q.directions.phi_o,
                               "Relative azimuth |φo − φi|, deg (180 = specular side); φi = 0");
  auto* phi_i = truth.add_option("--phi-i", q.directions.phi_i, "Incident azimuth, deg");
  auto* phi_o = truth.add_option("--phi-o", q.directions.phi_o, "Outgoing azimuth, deg");
  phi->excludes(phi_i)->excludes(phi_o);
  truth.add_flag("--anisotropic", q.anisotropic, "The brushed (anisotropic) sample");
  truth.add_flag("--glossy", q.glossy, "The glossy isotropic sample");
  truth.add_option("--material", q.material_path, "The sample in this material file");
  truth.add_flag("--json", q.json, "Print JSON instead of two columns");
}

FunctionCodes StageFunctionCodes(const SimConfig& c) {
  std::string error;
  return ParseFunctionCodes(c.stage_function_codes, &error).value_or(kServedFunctionCodes);
}

SimWordOrder StageWordOrder(const SimConfig& c) {
  return c.stage_word_order == "lower_first" ? SimWordOrder::kLowFirst : SimWordOrder::kHighFirst;
}

namespace {
const std::map<std::string, SimRampUnit>& RampUnits() {
  static const std::map<std::string, SimRampUnit> units = {
      {"khz_per_s", SimRampUnit::kKhzPerSecond},
      {"s", SimRampUnit::kSeconds},
      {"ms_per_khz", SimRampUnit::kMsPerKhz}};
  return units;
}
}  // namespace

SimRampUnit StageRampUnit(const SimConfig& c) {
  const auto it = RampUnits().find(c.stage_ramp_unit);
  return it == RampUnits().end() ? SimRampUnit::kKhzPerSecond : it->second;
}

namespace {

// The run: time scale, the Modbus endpoint, the sample, the operator's detector, the PR-650 link.
Status ValidateRun(const SimConfig& c) {
  if (!Finite(c.time_scale) || c.time_scale <= 0) {
    return InvalidArgument("time scale " + std::to_string(c.time_scale) +
                           " is not positive; use --time-scale > 0 (1 = real time)");
  }
  if (c.modbus_port < 0 || c.modbus_port > 65535) {
    return InvalidArgument("Modbus port " + std::to_string(c.modbus_port) +
                           " is out of range; use 0 (any free port) to 65535");
  }
  if (c.modbus_host.empty()) return InvalidArgument("Modbus host is empty; use --modbus-host");
  if (c.optics.anisotropic && c.optics.glossy) {
    return InvalidArgument(
        "--anisotropic and --glossy name two samples; mount one (the glossy sample is isotropic)");
  }
  if (!c.optics.material_path.empty() && (c.optics.anisotropic || c.optics.glossy)) {
    return InvalidArgument(
        "--material and --anisotropic/--glossy name two samples; mount one (deploy/materials/ "
        "has brushed.toml and glossy.toml)");
  }
  if (!Finite(c.manual_delta_deg) || c.manual_delta_deg < 0 || c.manual_delta_deg > 180) {
    return InvalidArgument("manual detector angle must be 0–180 deg; fix --manual-delta");
  }
  if (c.fifo_bytes < 1 || c.fifo_bytes > 4096) {
    return InvalidArgument(
        "PR-650 fifo_bytes must be 1–4096 (14: a 16550 UART; 1: byte by byte); "
        "fix [pr650] fifo_bytes or --fifo-bytes");
  }
  if (!Finite(c.wake_window_s) || c.wake_window_s < 0) {
    return InvalidArgument("wake window must be >= 0 s; fix --wake-window");
  }
  return Status::Ok();
}

// Each axis's homing speed and travel limits.
Status ValidateAxes(const SimConfig& c) {
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const AxisSettings& a = c.axes[i];
    const std::string n = kAxisNames[i];
    if (!Finite(a.home_speed_deg_s) || a.home_speed_deg_s <= 0) {
      return InvalidArgument("axis " + n + ": homing speed must be > 0 deg/s; fix --" + n +
                             "-home-speed");
    }
    if (!Finite(a.min_deg) || !Finite(a.max_deg) || a.min_deg >= a.max_deg) {
      return InvalidArgument("axis " + n + ": travel limits need min < max; fix --" + n +
                             "-min/--" + n + "-max");
    }
  }
  return Status::Ok();
}

// The faults to inject on the serial line and the Modbus link.
Status ValidateFaults(const SimConfig& c) {
  const SerialFaults& s = c.serial_faults;
  if (s.garbage_next < 0 || s.truncate_next < 0 || s.quality_count < 0 ||
      !Finite(s.vanish_seconds) || s.vanish_seconds < 0) {
    return InvalidArgument("serial fault counts and durations must be >= 0");
  }
  // The meter's own code: a PR-650 quality code (18), a CS-2000 ERxx number (10 → ER10), both
  // two digits; a PR-670 result code (−8, up to five characters).
  const bool pr670 = MeterFamilyOf(c.meter) == "pr670";
  if (pr670 ? (s.quality_code < -9999 || s.quality_code > 99999)
            : (s.quality_code < 0 || s.quality_code > 99)) {
    return InvalidArgument(pr670 ? "serial fault quality code must be a PR-670 result code "
                                   "(−9999 … 99999, e.g. −8)"
                                 : "serial fault quality code must be 0–99 (a PR-650 code such "
                                   "as 18, a CS-2000 ERxx number such as 10)");
  }
  const ModbusFaults& m = c.modbus_faults;
  if (m.exception_count < 0 || m.late_count < 0 || m.late_reply_ms < 0) {
    return InvalidArgument("Modbus fault counts and delays must be >= 0");
  }
  if (m.exception_code < 0 || m.exception_code > 255) {
    return InvalidArgument("Modbus fault exception code must be 0–255 (usually 2, 4 or 6)");
  }
  return Status::Ok();
}

// The stage controller's register conventions: function codes, word order, ramp unit.
Status ValidateStageRegisters(const SimConfig& c) {
  std::string error;
  if (!ParseFunctionCodes(c.stage_function_codes, &error)) {
    return InvalidArgument("stage function codes '" + c.stage_function_codes + "': " + error +
                           "; fix [stage] function_codes or --stage-function-codes");
  }
  if (c.stage_word_order != "upper_first" && c.stage_word_order != "lower_first") {
    return InvalidArgument("stage word order '" + c.stage_word_order +
                           "' is unknown; use upper_first or lower_first ([stage] word_order, "
                           "--stage-word-order)");
  }
  if (RampUnits().count(c.stage_ramp_unit) == 0) {
    return InvalidArgument("stage ramp unit '" + c.stage_ramp_unit +
                           "' is unknown; use khz_per_s, s or ms_per_khz ([stage] ramp_unit, "
                           "--stage-ramp-unit)");
  }
  return Status::Ok();
}

// The optics: noise, stray light, the white standard, the lamp, the detector.
Status ValidateOptics(const SimConfig& c) {
  const OpticsConfig& o = c.optics;
  if (!Finite(o.noise_scale) || o.noise_scale < 0) {
    return InvalidArgument("noise scale must be >= 0 (0 = noiseless)");
  }
  if (!Finite(o.ambient_radiance) || o.ambient_radiance < 0) {
    return InvalidArgument("optics.ambient_radiance must be >= 0 W·m⁻²·sr⁻¹·nm⁻¹");
  }
  if (!Finite(o.white_reflectance) || o.white_reflectance <= 0 || o.white_reflectance > 1) {
    return InvalidArgument("optics.white_reflectance must be in (0, 1]");
  }
  if (!(o.lamp.color_temperature_k > 0) || !(o.lamp.irradiance_at_560nm > 0)) {
    return InvalidArgument("optics.lamp: colour temperature and irradiance must be > 0");
  }
  const DetectorConfig& d = o.detector;
  if (!(d.full_scale > 0) || !(d.adaptive_fill > 0) || d.adaptive_fill > 1 ||
      !(d.full_well_counts > 0) || d.read_noise_counts < 0 || d.weak_fill < 0 ||
      d.low_light_fill < d.weak_fill || !(d.overhead_s >= 0) || d.min_integration_ms < 1 ||
      d.max_integration_ms < d.min_integration_ms) {
    return InvalidArgument(
        "optics.detector: need full_scale > 0, 0 < adaptive_fill <= 1, full_well_counts > 0, "
        "read_noise_counts >= 0, 0 <= weak_fill <= low_light_fill, overhead_s >= 0, "
        "1 <= min_integration_ms <= max_integration_ms");
  }
  return ValidateErrorSources(o.errors);
}

Status ValidateLogLevel(const SimConfig& c) {
  static const char* const kLevels[] = {"trace", "debug", "info", "warn", "error", "off"};
  bool level_ok = false;
  for (const char* l : kLevels) level_ok = level_ok || c.log_level == l;
  if (!level_ok) {
    return InvalidArgument("log level '" + c.log_level +
                           "' is unknown; use trace, debug, info, warn, error or off");
  }
  return Status::Ok();
}

}  // namespace

Status ValidateConfig(const SimConfig& c) {
  for (Status (*check)(const SimConfig&) :
       {ValidateRun, ValidateAxes, ValidateFaults, ValidateStageRegisters, ValidateOptics,
        ValidateLogLevel}) {
    if (Status st = check(c); !st.ok()) return st;
  }
  return Status::Ok();
}

}  // namespace brdf::sim
