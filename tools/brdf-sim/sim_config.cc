#include "tools/brdf-sim/sim_config.h"

#include <toml++/toml.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>
#include <sstream>
#include <string_view>

namespace brdf::sim {
namespace {

// ---- TOML reading: every key is checked, every type error names the key and the file. ----

class TomlReader {
 public:
  explicit TomlReader(std::string source) : source_(std::move(source)) {}

  // Errors on keys of `table` outside `known`.
  Status CheckKeys(const toml::table& table, std::string_view where,
                   std::initializer_list<std::string_view> known) const {
    for (const auto& [key, node] : table) {
      bool found = false;
      for (std::string_view k : known) found = found || key.str() == k;
      if (!found) {
        std::string allowed;
        for (std::string_view k : known) allowed += (allowed.empty() ? "" : ", ") + std::string(k);
        return InvalidArgument(source_ + ": unknown key '" + Path(where, key.str()) +
                               "'; expected one of: " + allowed +
                               " (see tools/brdf-sim/README.md)");
      }
    }
    return Status::Ok();
  }

  Status Read(const toml::table& t, std::string_view where, std::string_view key,
              double& out) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return Status::Ok();
    if (auto v = n->value<double>()) {  // integers convert too
      out = *v;
      return Status::Ok();
    }
    return TypeError(where, key, "a number");
  }
  Status Read(const toml::table& t, std::string_view where, std::string_view key, int& out) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return Status::Ok();
    if (const auto* v = n->as_integer()) {
      const std::int64_t x = v->get();
      if (x < INT32_MIN || x > INT32_MAX) return TypeError(where, key, "an integer in int range");
      out = static_cast<int>(x);
      return Status::Ok();
    }
    return TypeError(where, key, "an integer");
  }
  Status Read(const toml::table& t, std::string_view where, std::string_view key,
              std::uint64_t& out) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return Status::Ok();
    if (const auto* v = n->as_integer(); v != nullptr && v->get() >= 0) {
      out = static_cast<std::uint64_t>(v->get());
      return Status::Ok();
    }
    return TypeError(where, key, "a non-negative integer");
  }
  Status Read(const toml::table& t, std::string_view where, std::string_view key, bool& out) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return Status::Ok();
    if (const auto* v = n->as_boolean()) {
      out = v->get();
      return Status::Ok();
    }
    return TypeError(where, key, "true or false");
  }
  Status Read(const toml::table& t, std::string_view where, std::string_view key,
              std::string& out) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return Status::Ok();
    if (const auto* v = n->as_string()) {
      out = v->get();
      return Status::Ok();
    }
    return TypeError(where, key, "a string");
  }

  // The sub-table `key` of `t`, or nullptr when absent; an error when `key` is not a table.
  Result<const toml::table*> Table(const toml::table& t, std::string_view where,
                                   std::string_view key) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return static_cast<const toml::table*>(nullptr);
    if (const auto* tab = n->as_table()) return tab;
    return TypeError(where, key, "a table ([" + Path(where, key) + "])");
  }

  const std::string& source() const { return source_; }

 private:
  static std::string Path(std::string_view where, std::string_view key) {
    return where.empty() ? std::string(key) : std::string(where) + "." + std::string(key);
  }
  Status TypeError(std::string_view where, std::string_view key, const std::string& what) const {
    return InvalidArgument(source_ + ": '" + Path(where, key) + "' must be " + what);
  }

  std::string source_;
};

// A fault code given without its count means "the next one".
void DefaultCount(int code, int& count) {
  if (code != 0 && count == 0) count = 1;
}

Status ReadFaults(const TomlReader& r, const toml::table& faults, SimConfig& c) {
  BRDF_RETURN_IF_ERROR(r.CheckKeys(faults, "faults", {"serial", "modbus"}));
  auto serial = r.Table(faults, "faults", "serial");
  if (!serial.ok()) return serial.status();
  if (const toml::table* s = *serial) {
    const char* w = "faults.serial";
    SerialFaults& f = c.serial_faults;
    BRDF_RETURN_IF_ERROR(r.CheckKeys(*s, w,
                                     {"silent", "garbage_next", "truncate_next", "quality_code",
                                      "quality_count", "vanish_seconds"}));
    BRDF_RETURN_IF_ERROR(r.Read(*s, w, "silent", f.silent));
    BRDF_RETURN_IF_ERROR(r.Read(*s, w, "garbage_next", f.garbage_next));
    BRDF_RETURN_IF_ERROR(r.Read(*s, w, "truncate_next", f.truncate_next));
    BRDF_RETURN_IF_ERROR(r.Read(*s, w, "quality_code", f.quality_code));
    BRDF_RETURN_IF_ERROR(r.Read(*s, w, "quality_count", f.quality_count));
    BRDF_RETURN_IF_ERROR(r.Read(*s, w, "vanish_seconds", f.vanish_seconds));
    if (s->get("quality_count") == nullptr) DefaultCount(f.quality_code, f.quality_count);
  }
  auto modbus = r.Table(faults, "faults", "modbus");
  if (!modbus.ok()) return modbus.status();
  if (const toml::table* m = *modbus) {
    const char* w = "faults.modbus";
    ModbusFaults& f = c.modbus_faults;
    BRDF_RETURN_IF_ERROR(r.CheckKeys(*m, w,
                                     {"exception_code", "exception_count", "late_reply_ms",
                                      "late_count", "drop_connection", "alarm_mid_move", "stall"}));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "exception_code", f.exception_code));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "exception_count", f.exception_count));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "late_reply_ms", f.late_reply_ms));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "late_count", f.late_count));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "drop_connection", f.drop_connection));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "alarm_mid_move", f.alarm_mid_move));
    BRDF_RETURN_IF_ERROR(r.Read(*m, w, "stall", f.stall));
    if (m->get("exception_count") == nullptr) DefaultCount(f.exception_code, f.exception_count);
    if (m->get("late_count") == nullptr) DefaultCount(f.late_reply_ms, f.late_count);
  }
  return Status::Ok();
}

Status ReadOptics(const TomlReader& r, const toml::table& o, OpticsConfig& c) {
  BRDF_RETURN_IF_ERROR(r.CheckKeys(
      o, "optics", {"white_reflectance", "ambient_radiance", "noise_scale", "lamp", "detector"}));
  BRDF_RETURN_IF_ERROR(r.Read(o, "optics", "white_reflectance", c.white_reflectance));
  BRDF_RETURN_IF_ERROR(r.Read(o, "optics", "ambient_radiance", c.ambient_radiance));
  BRDF_RETURN_IF_ERROR(r.Read(o, "optics", "noise_scale", c.noise_scale));
  auto lamp = r.Table(o, "optics", "lamp");
  if (!lamp.ok()) return lamp.status();
  if (const toml::table* l = *lamp) {
    const char* w = "optics.lamp";
    BRDF_RETURN_IF_ERROR(r.CheckKeys(*l, w, {"color_temperature_k", "irradiance_at_560nm"}));
    BRDF_RETURN_IF_ERROR(r.Read(*l, w, "color_temperature_k", c.lamp.color_temperature_k));
    BRDF_RETURN_IF_ERROR(r.Read(*l, w, "irradiance_at_560nm", c.lamp.irradiance_at_560nm));
  }
  auto detector = r.Table(o, "optics", "detector");
  if (!detector.ok()) return detector.status();
  if (const toml::table* d = *detector) {
    const char* w = "optics.detector";
    DetectorConfig& dc = c.detector;
    BRDF_RETURN_IF_ERROR(r.CheckKeys(
        *d, w,
        {"full_scale", "adaptive_fill", "low_light_fill", "weak_fill", "full_well_counts",
         "read_noise_counts", "min_integration_ms", "max_integration_ms", "overhead_s"}));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "full_scale", dc.full_scale));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "adaptive_fill", dc.adaptive_fill));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "low_light_fill", dc.low_light_fill));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "weak_fill", dc.weak_fill));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "full_well_counts", dc.full_well_counts));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "read_noise_counts", dc.read_noise_counts));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "min_integration_ms", dc.min_integration_ms));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "max_integration_ms", dc.max_integration_ms));
    BRDF_RETURN_IF_ERROR(r.Read(*d, w, "overhead_s", dc.overhead_s));
  }
  return Status::Ok();
}

Status ReadTable(const TomlReader& r, const toml::table& root, SimConfig& c) {
  BRDF_RETURN_IF_ERROR(r.CheckKeys(root, "",
                                   {"time_scale", "seed", "anisotropic", "glossy", "mounted",
                                    "log_level", "modbus", "pr650", "stage", "faults", "optics"}));
  BRDF_RETURN_IF_ERROR(r.Read(root, "", "time_scale", c.time_scale));
  BRDF_RETURN_IF_ERROR(r.Read(root, "", "seed", c.optics.seed));
  BRDF_RETURN_IF_ERROR(r.Read(root, "", "anisotropic", c.optics.anisotropic));
  BRDF_RETURN_IF_ERROR(r.Read(root, "", "glossy", c.optics.glossy));
  BRDF_RETURN_IF_ERROR(r.Read(root, "", "log_level", c.log_level));
  std::string mounted;
  BRDF_RETURN_IF_ERROR(r.Read(root, "", "mounted", mounted));
  if (!mounted.empty()) {
    auto t = ParseMountedTarget(mounted);
    if (!t) {
      return InvalidArgument(r.source() + ": 'mounted' is \"" + mounted +
                             "\"; expected \"sample\", \"white\" or \"dark\"");
    }
    c.mounted = *t;
  }

  auto modbus = r.Table(root, "", "modbus");
  if (!modbus.ok()) return modbus.status();
  if (const toml::table* m = *modbus) {
    BRDF_RETURN_IF_ERROR(r.CheckKeys(*m, "modbus", {"host", "port", "rtu"}));
    BRDF_RETURN_IF_ERROR(r.Read(*m, "modbus", "host", c.modbus_host));
    BRDF_RETURN_IF_ERROR(r.Read(*m, "modbus", "port", c.modbus_port));
    BRDF_RETURN_IF_ERROR(r.Read(*m, "modbus", "rtu", c.rtu));
  }

  auto pr650 = r.Table(root, "", "pr650");
  if (!pr650.ok()) return pr650.status();
  if (const toml::table* p = *pr650) {
    BRDF_RETURN_IF_ERROR(r.CheckKeys(*p, "pr650",
                                     {"pacing", "fifo_bytes", "wake_window_s", "link",
                                      "d5_header_bare_cr", "m0_reply_is_quality"}));
    BRDF_RETURN_IF_ERROR(r.Read(*p, "pr650", "d5_header_bare_cr", c.d5_header_bare_cr));
    BRDF_RETURN_IF_ERROR(r.Read(*p, "pr650", "m0_reply_is_quality", c.m0_reply_is_quality));
    BRDF_RETURN_IF_ERROR(r.Read(*p, "pr650", "link", c.pr650_link));
    BRDF_RETURN_IF_ERROR(r.Read(*p, "pr650", "pacing", c.pacing));
    BRDF_RETURN_IF_ERROR(r.Read(*p, "pr650", "fifo_bytes", c.fifo_bytes));
    BRDF_RETURN_IF_ERROR(r.Read(*p, "pr650", "wake_window_s", c.wake_window_s));
  }

  auto stage = r.Table(root, "", "stage");
  if (!stage.ok()) return stage.status();
  if (const toml::table* s = *stage) {
    BRDF_RETURN_IF_ERROR(
        r.CheckKeys(*s, "stage",
                    {"detector_arm", "manual_delta_deg", "function_codes", "word_order",
                     "ramp_unit", "alpha", "beta", "gamma", "delta"}));
    BRDF_RETURN_IF_ERROR(r.Read(*s, "stage", "ramp_unit", c.stage_ramp_unit));
    BRDF_RETURN_IF_ERROR(r.Read(*s, "stage", "function_codes", c.stage_function_codes));
    BRDF_RETURN_IF_ERROR(r.Read(*s, "stage", "word_order", c.stage_word_order));
    BRDF_RETURN_IF_ERROR(r.Read(*s, "stage", "detector_arm", c.detector_arm));
    BRDF_RETURN_IF_ERROR(r.Read(*s, "stage", "manual_delta_deg", c.manual_delta_deg));
    for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
      auto axis = r.Table(*s, "stage", kAxisNames[i]);
      if (!axis.ok()) return axis.status();
      const toml::table* a = *axis;
      if (a == nullptr) continue;
      const std::string w = std::string("stage.") + kAxisNames[i];
      BRDF_RETURN_IF_ERROR(r.CheckKeys(*a, w, {"home_speed_deg_s", "min_deg", "max_deg"}));
      BRDF_RETURN_IF_ERROR(r.Read(*a, w, "home_speed_deg_s", c.axes[i].home_speed_deg_s));
      BRDF_RETURN_IF_ERROR(r.Read(*a, w, "min_deg", c.axes[i].min_deg));
      BRDF_RETURN_IF_ERROR(r.Read(*a, w, "max_deg", c.axes[i].max_deg));
    }
  }

  auto faults = r.Table(root, "", "faults");
  if (!faults.ok()) return faults.status();
  if (const toml::table* f = *faults) BRDF_RETURN_IF_ERROR(ReadFaults(r, *f, c));

  auto optics = r.Table(root, "", "optics");
  if (!optics.ok()) return optics.status();
  if (const toml::table* o = *optics) BRDF_RETURN_IF_ERROR(ReadOptics(r, *o, c.optics));
  return Status::Ok();
}

bool Finite(double x) {
  return std::isfinite(x);
}

}  // namespace

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
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << source_name << ":" << e.source().begin.line << ":" << e.source().begin.column
        << ": not valid TOML: " << e.description() << "; fix the file or drop --config";
    return InvalidArgument(msg.str());
  }
  SimConfig updated = config;
  BRDF_RETURN_IF_ERROR(ReadTable(TomlReader(source_name), root, updated));
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
  return LoadConfigString(text.str(), path, config);
}

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
  app.add_option("--stage-function-codes", c.stage_function_codes,
                 "Function codes the drives answer: az (3,6,8,16), leadshine, moons, or a list");
  app.add_option("--stage-word-order", c.stage_word_order,
                 "32-bit values in two registers: upper_first (AZ default) or lower_first");
  app.add_option("--stage-ramp-unit", c.stage_ramp_unit,
                 "Unit of the drives' ramp rates: khz_per_s (AZ default), s or ms_per_khz");
  app.add_flag("--anisotropic", c.optics.anisotropic, "Mount the brushed (anisotropic) sample");
  app.add_flag("--glossy", c.optics.glossy,
               "Mount the glossy isotropic sample (AnalyticBrdf::Glossy: the paint's base under a "
               "lobe of exponent 200)");
  const std::map<std::string, MountedTarget> targets = {{"sample", MountedTarget::kSample},
                                                        {"white", MountedTarget::kWhite},
                                                        {"dark", MountedTarget::kDark}};
  app.add_option("--mounted", c.mounted, "What is on the holder at start: sample, white or dark")
      ->transform(CLI::CheckedTransformer(targets, CLI::ignore_case));
  app.add_option("--noise-scale", c.optics.noise_scale, "Scale the meter's noise (0 = none)");
  app.add_option("--log-level", c.log_level, "trace, debug, info, warn, error or off");

  for (std::size_t i = 0; i < kAxisNames.size(); ++i) {
    const std::string n = kAxisNames[i];
    app.add_option("--" + n + "-home-speed", c.axes[i].home_speed_deg_s,
                   "Homing speed of " + n + ", deg/s (moves run at the speed the driver writes)");
    app.add_option("--" + n + "-min", c.axes[i].min_deg, "Lower travel limit of " + n + ", deg");
    app.add_option("--" + n + "-max", c.axes[i].max_deg, "Upper travel limit of " + n + ", deg");
  }

  SerialFaults& s = c.serial_faults;
  app.add_flag("--serial-silent", s.silent, "Fault: the PR-650 answers nothing");
  app.add_option("--serial-garbage-next", s.garbage_next, "Fault: next N replies are garbage");
  app.add_option("--serial-truncate-next", s.truncate_next, "Fault: next N replies stop half-way");
  app.add_option("--serial-quality-code", s.quality_code, "Fault: force this quality code ...");
  app.add_option("--serial-quality-count", s.quality_count,
                 "... for the next N measurements (default 1 when a code is given)");
  app.add_option("--serial-vanish-seconds", s.vanish_seconds,
                 "Fault: the pty vanishes during the next D5, back after S seconds");
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

Status ValidateConfig(const SimConfig& c) {
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
  const SerialFaults& s = c.serial_faults;
  if (s.garbage_next < 0 || s.truncate_next < 0 || s.quality_count < 0 ||
      !Finite(s.vanish_seconds) || s.vanish_seconds < 0) {
    return InvalidArgument("serial fault counts and durations must be >= 0");
  }
  if (s.quality_code < 0 || s.quality_code > 99) {
    return InvalidArgument("serial fault quality code must be 0–99 (a PR-650 code such as 18)");
  }
  const ModbusFaults& m = c.modbus_faults;
  if (m.exception_count < 0 || m.late_count < 0 || m.late_reply_ms < 0) {
    return InvalidArgument("Modbus fault counts and delays must be >= 0");
  }
  if (m.exception_code < 0 || m.exception_code > 255) {
    return InvalidArgument("Modbus fault exception code must be 0–255 (usually 2, 4 or 6)");
  }
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
  static const char* const kLevels[] = {"trace", "debug", "info", "warn", "error", "off"};
  bool level_ok = false;
  for (const char* l : kLevels) level_ok = level_ok || c.log_level == l;
  if (!level_ok) {
    return InvalidArgument("log level '" + c.log_level +
                           "' is unknown; use trace, debug, info, warn, error or off");
  }
  return Status::Ok();
}

}  // namespace brdf::sim
