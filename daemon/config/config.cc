#include "daemon/config/config.h"

#include <toml++/toml.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "core/toml/table_reader.h"

namespace brdf::daemon {
namespace {

using toml_keys::Problems;
using toml_keys::TableReader;

// What a refused file's message ends with.
constexpr const char* kAdvice =
    "fix the file; brdfd.example.toml (deploy/, installed in share/doc/brdfd/) shows every key "
    "with its default";

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// "host:port" with a port in [min_port, 65535]; false with a reason otherwise.
bool SplitHostPort(const std::string& s, int min_port, std::string& host, int& port,
                   std::string& reason) {
  const std::size_t colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == s.size()) {
    reason = "\"" + s + "\" is not host:port";
    return false;
  }
  const std::string digits = s.substr(colon + 1);
  if (digits.size() > 5 || digits.find_first_not_of("0123456789") != std::string::npos) {
    reason = "\"" + s + "\" has no numeric port after the last ':'";
    return false;
  }
  const int p = std::stoi(digits);
  if (p < min_port || p > 65535) {
    reason = "port " + digits + " is outside " + std::to_string(min_port) + " … 65535";
    return false;
  }
  host = s.substr(0, colon);
  port = p;
  return true;
}

// The names drivers::pr650::ParseQualityAction accepts, for messages.
const char* const kQualityActionNames =
    "accept, accept_and_flag, retry, retry_then_flag, adapt_integration, sync_off_and_retry, fail";

// [server] interpolate_cpus: CPU numbers 0 … kMaxCpuIndex − 1, at least one.
void ReadInterpolateCpus(TableReader& t, Problems& problems, Config& c) {
  const toml::node* cpus = t.Node("interpolate_cpus");
  if (cpus == nullptr) return;
  const toml::array* list = cpus->as_array();
  if (list == nullptr || list->empty()) {
    t.Issue("interpolate_cpus", "must be a non-empty array of CPU numbers, e.g. [1]");
    return;
  }
  for (const toml::node& cpu : *list) {
    const auto* n = cpu.as_integer();
    if (n == nullptr || n->get() < 0 || n->get() >= kMaxCpuIndex) {
      problems.Add(cpu.source(), t.KeyPath("interpolate_cpus"),
                   "holds " + (n ? std::to_string(n->get()) : std::string("a non-integer")) +
                       "; give CPU numbers 0 … " + std::to_string(kMaxCpuIndex - 1) +
                       " (as `nproc` and /proc/cpuinfo count them)");
      c.server.interpolate_cpus.clear();
      return;
    }
    c.server.interpolate_cpus.push_back(static_cast<int>(n->get()));
  }
}

// [server.tls]: cert and key together, client_ca optional.
void ReadTls(TableReader& server, Problems& problems, Config& c) {
  TableReader tls = server.Sub("tls");
  if (tls.table() == nullptr) return;
  TlsConfig cfg;
  const bool has_cert = tls.String("cert", cfg.cert);
  const bool has_key = tls.String("key", cfg.key);
  tls.String("client_ca", cfg.client_ca);
  if (has_cert != has_key) {
    problems.Add(tls.where(), has_cert ? "server.tls.key" : "server.tls.cert",
                 "missing; TLS needs both cert and key");
  } else if (!has_cert) {
    problems.Add(tls.where(), "server.tls",
                 "has neither cert nor key; give both, or remove [server.tls] for plaintext");
  } else {
    c.server.tls = cfg;
  }
  tls.Finish();
}

void ReadServer(TableReader& root, Problems& problems, Config& c) {
  TableReader t = root.Sub("server");
  std::string listen;
  if (t.String("listen", listen)) {
    std::string host, reason;
    int port = 0;
    if (listen.rfind("unix:", 0) == 0) {
      if (listen.size() == 5)
        t.Issue("listen", "\"unix:\" needs a socket path");
      else
        c.server.listen = listen;
    } else if (!SplitHostPort(listen, 0, host, port, reason)) {
      t.Issue("listen", reason + "; give e.g. \"127.0.0.1:50051\"");
    } else {
      c.server.listen = listen;
    }
  }
  t.Int("interpolate_threads", c.server.interpolate_threads, 1, 64);
  t.Int("max_streams_per_token", c.server.max_streams_per_token, 1, 100000);
  t.Int("max_streams_analyst", c.server.max_streams_analyst, 0, 100000);
  t.Int("max_streams_operator", c.server.max_streams_operator, 1, 100000);
  t.Int("max_streams_unauthenticated", c.server.max_streams_unauthenticated, 0, 100000);
  t.Int("stream_stall_timeout_s", c.server.stream_stall_timeout_s, 1, 86400);
  t.Int("memory_budget_mb", c.server.memory_budget_mb, 16, 1048576);
  ReadInterpolateCpus(t, problems, c);
  ReadTls(t, problems, c);
  t.Finish();
}

void ReadWeb(TableReader& root, Config& c) {
  TableReader t = root.Sub("web");
  std::string listen;
  if (t.String("listen", listen)) {
    std::string host, reason;
    int port = 0;
    if (!SplitHostPort(listen, 0, host, port, reason)) {
      t.Issue("listen", reason + "; give e.g. \"127.0.0.1:8080\"");
    } else {
      c.web.listen = listen;
    }
  }
  t.String("root", c.web.root);
  t.Finish();
}

// [meter.quality]: code = "action", or code = { action = "…", accept_flagged_when_exhausted }.
void ReadQualityRules(TableReader& meter, Problems& problems, MeterConfig& m) {
  const toml::table* q = meter.Table("quality");
  if (q == nullptr) return;
  for (const auto& [key, node] : *q) {
    const std::string code_text(key.str());
    const std::string path = "meter.quality." + code_text;
    if (code_text.empty() || code_text.size() > 2 ||
        code_text.find_first_not_of("0123456789") != std::string::npos) {
      problems.Add(key.source(), path, "is not a quality code; use the code's number 0 … 99");
      continue;
    }
    drivers::pr650::QualityRule rule;
    std::string action;
    if (node.is_string()) {
      action = node.as_string()->get();
    } else if (node.is_table()) {
      TableReader r(problems, node.as_table(), path);
      if (r.Require("action", "give one of " + std::string(kQualityActionNames))) {
        r.String("action", action);
      }
      r.Bool("accept_flagged_when_exhausted", rule.accept_flagged_when_exhausted);
      r.Finish();
    } else {
      problems.Add(node.source(), path,
                   std::string("must be an action name or a table, not ") +
                       toml_keys::TypeName(node.type()));
      continue;
    }
    if (action.empty()) continue;
    const std::optional<drivers::pr650::QualityAction> parsed =
        drivers::pr650::ParseQualityAction(action);
    if (!parsed) {
      problems.Add(node.source(), path, "\"" + action + "\" is not one of " + kQualityActionNames);
      continue;
    }
    rule.action = *parsed;
    m.quality_overrides[std::stoi(code_text)] = rule;
  }
}

void ReadMeter(TableReader& root, Problems& problems, Config& c) {
  TableReader t = root.Sub("meter");
  MeterConfig& m = c.meter;
  std::string model;
  if (t.OneOf("model", model, {"pr650", "pr655", "pr670", "cs2000", "cs2000a", "cs3000"})) {
    m.model = *ParseMeterModel(model);
  }
  t.String("port", m.port);
  int baud = m.baud;
  if (t.Int("baud", baud, 1, 1000000)) {
    static constexpr int kBauds[] = {1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200};
    bool standard = false;
    for (int b : kBauds) standard |= b == baud;
    if (standard) {
      m.baud = baud;
    } else {
      t.Issue("baud", std::to_string(baud) +
                          " is not a standard rate (1200 … 115200; the PR-650 uses 9600)");
    }
  }
  t.Bool("hardware_flow_control", m.hardware_flow_control);
  t.Int("pacing_ms", m.pacing_ms, 0, 10000);
  t.Int("quiet_gap_ms", m.quiet_gap_ms, 1, 10000);
  t.Int("reply_timeout_ms", m.reply_timeout_ms, 100, 600000);
  t.Int("measurement_timeout_ms", m.measurement_timeout_ms, 1000, 600000);
  t.Int("wake_attempts", m.wake_attempts, 1, 20);
  t.Bool("measure_with_spectrum", m.measure_with_spectrum);
  t.Int("rts_settle_ms", m.rts_settle_ms, 0, 10000);
  t.Int("char_gap_ms", m.char_gap_ms, 0, 1000);
  t.OneOf("nd_filter", m.nd_filter, {"off", "on", "auto"});
  t.Int("overhead_ms", m.overhead_ms, 0, 60000);
  // The PR-650's integration range (S command: 10 … 6000 ms).
  t.Int("adaptive_reference_ms", m.adaptive_reference_ms, 10, 6000);
  t.Int("adaptive_dark_ms", m.adaptive_dark_ms, 10, 6000);
  t.Int("adaptive_sample_ms", m.adaptive_sample_ms, 10, 6000);
  ReadQualityRules(t, problems, m);
  t.Finish();
}

void ReadAxis(TableReader& axes, std::string_view name, AxisSettings& a, bool* present_given) {
  TableReader t = axes.Sub(name);
  *present_given = t.Bool("present", a.present);
  t.Int("unit_id", a.unit_id, 1, 247);
  t.Double("counts_per_degree", a.counts_per_degree, 0, 1e7, /*lo_open=*/true);
  t.Double("zero_offset_deg", a.zero_offset_deg, -360, 360);
  double sign = a.sign;
  if (t.Double("sign", sign, -1, 1)) {
    if (sign == 1 || sign == -1) {
      a.sign = sign;
    } else {
      t.Issue("sign", "must be 1 or -1, not " + Num(sign));
    }
  }
  const bool has_min = t.Double("min_deg", a.min_deg, -720, 720);
  const bool has_max = t.Double("max_deg", a.max_deg, -720, 720);
  if ((has_min || has_max) && a.min_deg >= a.max_deg) {
    t.Issue(has_max ? "max_deg" : "min_deg", "travel [" + Num(a.min_deg) + ", " + Num(a.max_deg) +
                                                 "] is empty; give min_deg < max_deg");
  }
  t.Double("speed_deg_s", a.speed_deg_s, 0, 360, /*lo_open=*/true);
  t.Finish();
}

// [stage.axes]: the four axes, then what must hold between them.
void ReadAxes(TableReader& stage, Problems& problems, StageConfig& s) {
  TableReader axes = stage.Sub("axes");
  bool given[4] = {};
  // A motorized detector arm is the δ axis; δ is present exactly when the arm is motorized.
  s.delta.present = s.detector_arm_motorized;
  ReadAxis(axes, "alpha", s.alpha, &given[0]);
  ReadAxis(axes, "beta", s.beta, &given[1]);
  ReadAxis(axes, "gamma", s.gamma, &given[2]);
  ReadAxis(axes, "delta", s.delta, &given[3]);
  axes.Finish();
  const toml::source_region where = axes.where();
  if (given[3] && s.delta.present != s.detector_arm_motorized) {
    problems.Add(where, "stage.axes.delta.present",
                 std::string(s.delta.present ? "true" : "false") +
                     " contradicts stage.detector_arm_motorized = " +
                     (s.detector_arm_motorized ? "true" : "false") +
                     "; the δ axis is the motorized detector arm");
  }
  if (!s.alpha.present || !s.beta.present) {
    problems.Add(where, !s.alpha.present ? "stage.axes.alpha.present" : "stage.axes.beta.present",
                 "must be true: the α and β stages are what the sample-rotation method turns");
  }
  std::map<int, std::string> units;
  const std::pair<const char*, const AxisSettings*> all[] = {
      {"alpha", &s.alpha}, {"beta", &s.beta}, {"gamma", &s.gamma}, {"delta", &s.delta}};
  for (const auto& [name, axis] : all) {
    if (!axis->present) continue;
    auto [it, inserted] = units.emplace(axis->unit_id, name);
    if (!inserted) {
      const toml::node* at = axes.table() ? (*axes.table())[name]["unit_id"].node() : nullptr;
      problems.Add(at ? at->source() : where, "stage.axes." + std::string(name) + ".unit_id",
                   std::to_string(axis->unit_id) + " is also the unit id of " + it->second +
                       "; every axis needs its own Modbus unit");
    }
  }
}

void ReadStage(TableReader& root, Problems& problems, Config& c) {
  TableReader t = root.Sub("stage");
  StageConfig& s = c.stage;
  t.OneOf("transport", s.transport, {"tcp", "rtu"});
  std::string address;
  if (t.String("address", address)) {
    std::string reason;
    if (!SplitHostPort(address, 1, s.host, s.port, reason)) {
      t.Issue("address", reason + "; give e.g. \"192.168.1.50:502\"");
    }
  }
  t.String("device", s.device);
  int baud = s.baud;
  if (t.Int("baud", baud, 1200, 1000000)) s.baud = baud;
  std::string parity;
  if (t.OneOf("parity", parity, {"N", "E", "O"})) s.parity = parity[0];
  t.OneOf("profile", s.profile, {"az", "leadshine", "moons"});
  if (t.String("profile_file", s.profile_file) && t.Node("profile") != nullptr) {
    t.Issue("profile_file",
            "given with profile; keep one: profile names a built-in map, profile_file a file");
  }
  t.Int("response_timeout_ms", s.response_timeout_ms, 10, 60000);
  t.Int("busy_window_ms", s.busy_window_ms, 0, 600000);
  t.Int("reconnect_max_ms", s.reconnect_max_ms, 100, 300000);
  t.Bool("detector_arm_motorized", s.detector_arm_motorized);
  if (s.transport == "rtu" && s.device.empty()) {
    t.Issue("device", "missing; transport \"rtu\" needs the serial device, e.g. \"/dev/ttyUSB1\"");
  }
  ReadAxes(t, problems, s);
  t.Finish();
}

// One [[auth.tokens]] table: a unique name, a long enough unique secret, a role.
void ReadToken(TableReader& r, std::set<std::string>& names, std::set<std::string>& secrets,
               Config& c) {
  TokenConfig tok;
  if (r.Require("name", "name the client") && r.String("name", tok.name) &&
      !names.insert(tok.name).second) {
    r.Issue("name", "\"" + tok.name + "\" is used by another token");
  }
  if (r.Require("token", "give the secret") && r.String("token", tok.token)) {
    if (tok.token.size() < kMinTokenLength) {
      r.Issue("token", "is " + std::to_string(tok.token.size()) + " characters; give at least " +
                           std::to_string(kMinTokenLength) + " (e.g. openssl rand -hex 24)");
    } else if (!secrets.insert(tok.token).second) {
      r.Issue("token", "is the same secret as another token's");
    }
  }
  std::string role;
  if (r.Require("role", "give \"operator\" or \"analyst\"") &&
      r.OneOf("role", role, {"operator", "analyst"})) {
    tok.role = role == "operator" ? Role::kOperator : Role::kAnalyst;
  }
  r.Finish();
  c.tokens.push_back(std::move(tok));
}

void ReadAuth(TableReader& root, Config& c) {
  TableReader t = root.Sub("auth");
  std::set<std::string> names;
  std::set<std::string> secrets;
  t.ArrayOfTables("tokens", "name, token and role",
                  [&](TableReader& r, std::size_t) { ReadToken(r, names, secrets, c); });
  t.Finish();
}

void ReadArchive(TableReader& root, Config& c) {
  TableReader t = root.Sub("archive");
  if (t.table() == nullptr) return;
  if (t.Require("credentials", "give the path of a file holding the archive's libpq conninfo")) {
    t.String("credentials", c.archive.credentials);
  }
  t.Int("batch_readings", c.archive.batch_readings, 1, 10000);
  t.Int("retry_ms", c.archive.retry_ms, 10, 600000);
  t.Finish();
}

// [uncertainty]: the terms of each reading's budget.
void ReadUncertainty(TableReader& root, Config& c) {
  TableReader t = root.Sub("uncertainty");
  UncertaintyConfig& u = c.uncertainty;
  t.Bool("enabled", u.enabled);
  t.Double("wavelength_nm", u.wavelength_nm, 0, 10);
  t.Double("stray_light", u.stray_light, 0, 0.1);
  t.Double("stage_repeatability_deg", u.stage_repeatability_deg, 0, 5);
  t.Double("stage_alignment_deg", u.stage_alignment_deg, 0, 5);
  double rate = 0;
  if (t.Double("lamp_drift_per_hour", rate, -0.5, 0.5)) u.lamp_drift_per_hour = rate;
  t.Double("meter_full_scale", u.meter_full_scale, 0, 1e6, /*lo_open=*/true);
  t.Double("meter_full_well_counts", u.meter_full_well_counts, 0, 1e12, /*lo_open=*/true);
  t.Double("meter_read_noise_counts", u.meter_read_noise_counts, 0, 1e9);
  t.Double("meter_adaptive_fill", u.meter_adaptive_fill, 0, 1, /*lo_open=*/true);
  t.Double("meter_gain_repeatability", u.meter_gain_repeatability, 0, 0.2);
  t.Finish();
}

// The small tables: [storage], [index], [export], [sample], [rig], [log].
void ReadOthers(TableReader& root, Config& c) {
  TableReader storage = root.Sub("storage");
  storage.String("database", c.storage.database);
  storage.Finish();
  TableReader index = root.Sub("index");
  index.Int("max_sessions", c.index.max_sessions, 1, 1024);
  index.Int("max_mb", c.index.max_mb, 16, 1048576);
  index.Finish();
  TableReader exports = root.Sub("export");
  exports.Int("max_entries", c.exports.max_entries, 1, 1024);
  exports.Int("max_mb", c.exports.max_mb, 0, 1048576);
  exports.Finish();
  TableReader sample = root.Sub("sample");
  sample.Double("white_reflectance", c.sample.white_reflectance, 0, 1, /*lo_open=*/true);
  sample.Double("white_reflectance_uncertainty", c.sample.white_reflectance_uncertainty, 0, 0.5);
  sample.Finish();
  TableReader rig = root.Sub("rig");
  rig.String("name", c.rig.name);
  rig.Double("time_scale", c.rig.time_scale, 0, 10000, /*lo_open=*/true);
  rig.Finish();
  TableReader log = root.Sub("log");
  log.OneOf("level", c.log.level, {"trace", "debug", "info", "warn", "error", "critical", "off"});
  log.Finish();
}

}  // namespace

namespace {

struct MeterModelNames {
  MeterModel model;
  const char* key;
  const char* name;
  MeterFamily family;
};
constexpr MeterModelNames kMeterModels[] = {
    {MeterModel::kPr650, "pr650", "PR-650", MeterFamily::kPr650},
    {MeterModel::kPr655, "pr655", "PR-655", MeterFamily::kPr670},
    {MeterModel::kPr670, "pr670", "PR-670", MeterFamily::kPr670},
    {MeterModel::kCs2000, "cs2000", "CS-2000", MeterFamily::kCs2000},
    {MeterModel::kCs2000A, "cs2000a", "CS-2000A", MeterFamily::kCs2000},
    {MeterModel::kCs3000, "cs3000", "CS-3000", MeterFamily::kCs2000},
};

const MeterModelNames& NamesOf(MeterModel model) {
  for (const MeterModelNames& m : kMeterModels) {
    if (m.model == model) return m;
  }
  return kMeterModels[0];
}

}  // namespace

const char* MeterModelKey(MeterModel model) {
  return NamesOf(model).key;
}

const char* MeterModelName(MeterModel model) {
  return NamesOf(model).name;
}

std::optional<MeterModel> ParseMeterModel(std::string_view key) {
  for (const MeterModelNames& m : kMeterModels) {
    if (key == m.key) return m.model;
  }
  return std::nullopt;
}

MeterFamily FamilyOf(MeterModel model) {
  return NamesOf(model).family;
}

const char* RoleName(Role role) {
  return role == Role::kOperator ? "operator" : "analyst";
}

Result<Config> ParseConfig(std::string_view toml_text, std::string_view source) {
  const std::string file = "config " + std::string(source);
  if (toml_text.size() > kMaxConfigBytes) {
    return ConfigurationError(file + ": " + std::to_string(toml_text.size()) +
                              " bytes, more than the " + std::to_string(kMaxConfigBytes) +
                              "-byte cap");
  }
  Problems problems(file, StatusCode::kConfigurationError, kAdvice);
  BRDF_ASSIGN_OR_RETURN(const toml::table doc, problems.Parse(toml_text, source));
  Config c;
  TableReader root(problems, &doc);
  ReadServer(root, problems, c);
  ReadMeter(root, problems, c);
  ReadStage(root, problems, c);
  ReadArchive(root, c);
  ReadAuth(root, c);
  ReadWeb(root, c);
  ReadOthers(root, c);
  ReadUncertainty(root, c);
  root.Finish();
  BRDF_RETURN_IF_ERROR(problems.status());
  return c;
}

Result<Config> LoadConfig(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    const int err = errno;
    const std::string why = std::strerror(err);
    if (err == ENOENT) {
      return NotFound("config " + path + ": no such file; give the path of brdfd's TOML file");
    }
    return IoError("config " + path + ": cannot open: " + why);
  }
  std::string text;
  char buf[8192];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    text.append(buf, n);
    if (text.size() > kMaxConfigBytes) break;
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) return IoError("config " + path + ": read error");
  return ParseConfig(text, path);
}

std::string RigName(const Config& config) {
  if (!config.rig.name.empty()) return config.rig.name;
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) == 0 && host[0] != '\0') return host;
  return "rig";
}

plan::RigDescription ToRigDescription(const Config& config) {
  plan::RigDescription rig;
  const StageConfig& s = config.stage;
  rig.has_gamma_axis = s.gamma.present;
  rig.has_detector_arm = s.detector_arm_motorized;
  auto travel = [](const AxisSettings& a) {
    return plan::AxisTravel{a.min_deg, a.max_deg, a.speed_deg_s};
  };
  rig.alpha = travel(s.alpha);
  rig.beta = travel(s.beta);
  rig.gamma = travel(s.gamma);
  rig.delta = travel(s.delta);
  auto convention = [](const AxisSettings& a) { return AxisConvention{a.sign, a.zero_offset_deg}; };
  rig.convention = {convention(s.alpha), convention(s.beta), convention(s.gamma),
                    convention(s.delta)};
  // The spectrum on the wire, 10 bits per byte (8N1): the PR-650's D5 report is ~1,730 bytes, a
  // PR-670's report 5 ~3,000 (201 bands), a CS-2000's four MEDR blocks ~4,500 (401 values).
  const MeterFamily family = FamilyOf(config.meter.model);
  const double report_bytes = family == MeterFamily::kPr650   ? 1730.0
                              : family == MeterFamily::kPr670 ? 3000.0
                                                              : 4500.0;
  rig.meter_transfer_s = report_bytes * 10.0 / config.meter.baud;
  // The meter's own time per reading and the integration it is expected to choose when adaptive
  // ([meter] overhead_ms, adaptive_*_ms); the daemon's own waits per exchange (M5; or M0 and
  // D5): the pacing before the command and the quiet gap that ends the reply. The move after a
  // reading starts once the measurement is held: after M5's status line, or M0's reply.
  rig.reading_overhead_s = config.meter.overhead_ms / 1000.0;
  rig.adaptive_integration = {.reference_s = config.meter.adaptive_reference_ms / 1000.0,
                              .dark_s = config.meter.adaptive_dark_ms / 1000.0,
                              .sample_s = config.meter.adaptive_sample_ms / 1000.0};
  const double pacing_s = config.meter.pacing_ms / 1000.0;
  const double gap_s = config.meter.quiet_gap_ms / 1000.0;
  const int exchanges = config.meter.measure_with_spectrum ? 1 : 2;
  rig.reading_host_s = exchanges * (pacing_s + gap_s);
  rig.reading_host_after_s = config.meter.measure_with_spectrum ? gap_s : pacing_s + gap_s;
  rig.time_scale = config.rig.time_scale;
  // stage_poll_s keeps RigDescription's default: the stage driver's poll_interval, which the
  // configuration does not set (tests/config checks they agree).
  return rig;
}

}  // namespace brdf::daemon
