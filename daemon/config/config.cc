#include "daemon/config/config.h"

#include <toml++/toml.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <set>
#include <string>
#include <utility>

namespace brdf::daemon {
namespace {

// Every problem of the file, each "line L, column C: key: reason".
class Issues {
 public:
  void Add(const toml::source_region& where, const std::string& key, const std::string& reason) {
    std::string at;
    if (where.begin.line > 0) {
      at = "line " + std::to_string(where.begin.line) + ", column " +
           std::to_string(where.begin.column) + ": ";
    }
    lines_.push_back(at + key + ": " + reason);
  }
  void AddUnknown(const toml::source_region& where, const std::string& key,
                  const std::string& known) {
    std::string at;
    if (where.begin.line > 0) {
      at = "line " + std::to_string(where.begin.line) + ", column " +
           std::to_string(where.begin.column) + ": ";
    }
    lines_.push_back(at + "unknown key " + key + " (known: " + known + ")");
  }
  bool empty() const { return lines_.empty(); }
  std::string Join(std::string_view source) const {
    std::string out;
    for (const std::string& l : lines_) {
      if (!out.empty()) out += "\n";
      out += "config " + std::string(source) + ": " + l;
    }
    return out;
  }

 private:
  std::vector<std::string> lines_;
};

std::string Join(std::initializer_list<std::string_view> items) {
  std::string out;
  for (std::string_view s : items) {
    if (!out.empty()) out += ", ";
    out += s;
  }
  return out;
}

const char* TypeName(toml::node_type type) {
  switch (type) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date/time";
  }
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Reads the keys of one table, remembering which keys it knows so that the rest can be
// reported as unknown. A missing table reads as empty: every key keeps its default.
class TableReader {
 public:
  TableReader(const toml::table* table, std::string path, Issues& issues)
      : table_(table), path_(std::move(path)), issues_(issues) {}

  std::string KeyPath(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  // The node at `key` (marked known), or nullptr when absent.
  const toml::node* Node(std::string_view key) {
    known_.insert(std::string(key));
    return table_ ? table_->get(key) : nullptr;
  }

  void Issue(const toml::node& node, std::string_view key, const std::string& reason) {
    issues_.Add(node.source(), KeyPath(key), reason);
  }

  bool WrongType(const toml::node& node, std::string_view key, const std::string& wanted) {
    Issue(node, key, "must be " + wanted + ", not " + TypeName(node.type()));
    return false;
  }

  // Each getter returns true when the key was present and valid (out updated).
  bool Bool(std::string_view key, bool& out) {
    const toml::node* n = Node(key);
    if (!n) return false;
    if (!n->is_boolean()) return WrongType(*n, key, "true or false");
    out = n->as_boolean()->get();
    return true;
  }

  bool Int(std::string_view key, int& out, long long lo, long long hi) {
    const toml::node* n = Node(key);
    if (!n) return false;
    if (!n->is_integer()) return WrongType(*n, key, "an integer");
    const long long v = n->as_integer()->get();
    if (v < lo || v > hi) {
      Issue(*n, key,
            std::to_string(v) + " is outside " + std::to_string(lo) + " … " + std::to_string(hi));
      return false;
    }
    out = static_cast<int>(v);
    return true;
  }

  // A finite number (integer or float) in [lo, hi], or (lo, hi] when lo_open.
  bool Double(std::string_view key, double& out, double lo, double hi, bool lo_open = false) {
    const toml::node* n = Node(key);
    if (!n) return false;
    double v = 0;
    if (n->is_integer()) {
      v = static_cast<double>(n->as_integer()->get());
    } else if (n->is_floating_point()) {
      v = n->as_floating_point()->get();
    } else {
      return WrongType(*n, key, "a number");
    }
    if (!std::isfinite(v)) {
      Issue(*n, key, "must be a finite number, not " + Num(v));
      return false;
    }
    if ((lo_open ? v <= lo : v < lo) || v > hi) {
      Issue(*n, key,
            Num(v) + " is outside " + std::string(lo_open ? "(" : "[") + Num(lo) + ", " + Num(hi) +
                "]");
      return false;
    }
    out = v;
    return true;
  }

  bool String(std::string_view key, std::string& out, bool allow_empty = false) {
    const toml::node* n = Node(key);
    if (!n) return false;
    if (!n->is_string()) return WrongType(*n, key, "a string");
    const std::string& v = n->as_string()->get();
    if (v.empty() && !allow_empty) {
      Issue(*n, key, "must not be empty");
      return false;
    }
    out = v;
    return true;
  }

  bool OneOf(std::string_view key, std::string& out,
             std::initializer_list<std::string_view> allowed) {
    std::string v;
    if (!String(key, v)) return false;
    for (std::string_view a : allowed) {
      if (v == a) {
        out = v;
        return true;
      }
    }
    Issue(*Node(key), key, "\"" + v + "\" is not one of " + Join(allowed));
    return false;
  }

  const toml::table* Table(std::string_view key) {
    const toml::node* n = Node(key);
    if (!n) return nullptr;
    if (!n->is_table()) {
      WrongType(*n, key, "a table");
      return nullptr;
    }
    return n->as_table();
  }

  const toml::array* Array(std::string_view key) {
    const toml::node* n = Node(key);
    if (!n) return nullptr;
    if (!n->is_array()) {
      WrongType(*n, key, "an array of tables ([[" + KeyPath(key) + "]])");
      return nullptr;
    }
    return n->as_array();
  }

  // Reports every key of the table that no getter asked for.
  void Finish() {
    if (!table_) return;
    std::string known;
    for (const std::string& k : known_) known += (known.empty() ? "" : ", ") + k;
    for (const auto& [key, node] : *table_) {
      if (known_.count(std::string(key.str())) == 0) {
        issues_.AddUnknown(key.source(), KeyPath(key.str()), known);
      }
    }
  }

 private:
  const toml::table* table_;
  std::string path_;
  Issues& issues_;
  std::set<std::string> known_;
};

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

void ReadServer(TableReader& root, Config& c, Issues& issues) {
  TableReader t(root.Table("server"), "server", issues);
  std::string listen;
  if (t.String("listen", listen)) {
    std::string host, reason;
    int port = 0;
    if (listen.rfind("unix:", 0) == 0) {
      if (listen.size() == 5)
        t.Issue(*t.Node("listen"), "listen", "\"unix:\" needs a socket path");
      else
        c.server.listen = listen;
    } else if (!SplitHostPort(listen, 0, host, port, reason)) {
      t.Issue(*t.Node("listen"), "listen", reason + "; give e.g. \"127.0.0.1:50051\"");
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
  if (const toml::node* cpus = t.Node("interpolate_cpus")) {
    const toml::array* list = cpus->as_array();
    if (list == nullptr || list->empty()) {
      t.Issue(*cpus, "interpolate_cpus", "must be a non-empty array of CPU numbers, e.g. [1]");
    } else {
      for (const toml::node& cpu : *list) {
        const auto* n = cpu.as_integer();
        if (n == nullptr || n->get() < 0 || n->get() >= kMaxCpuIndex) {
          t.Issue(cpu, "interpolate_cpus",
                  "holds " + (n ? std::to_string(n->get()) : std::string("a non-integer")) +
                      "; give CPU numbers 0 … " + std::to_string(kMaxCpuIndex - 1) +
                      " (as `nproc` and /proc/cpuinfo count them)");
          c.server.interpolate_cpus.clear();
          break;
        }
        c.server.interpolate_cpus.push_back(static_cast<int>(n->get()));
      }
    }
  }
  if (const toml::table* tls_table = t.Table("tls")) {
    TableReader tls(tls_table, "server.tls", issues);
    TlsConfig cfg;
    const bool has_cert = tls.String("cert", cfg.cert);
    const bool has_key = tls.String("key", cfg.key);
    tls.String("client_ca", cfg.client_ca);
    if (has_cert != has_key) {
      issues.Add(tls_table->source(), has_cert ? "server.tls.key" : "server.tls.cert",
                 "missing; TLS needs both cert and key");
    } else if (!has_cert) {
      issues.Add(tls_table->source(), "server.tls",
                 "has neither cert nor key; give both, or remove [server.tls] for plaintext");
    } else {
      c.server.tls = cfg;
    }
    tls.Finish();
  }
  t.Finish();
}

void ReadWeb(TableReader& root, Config& c, Issues& issues) {
  TableReader t(root.Table("web"), "web", issues);
  std::string listen;
  if (t.String("listen", listen)) {
    std::string host, reason;
    int port = 0;
    if (!SplitHostPort(listen, 0, host, port, reason)) {
      t.Issue(*t.Node("listen"), "listen", reason + "; give e.g. \"127.0.0.1:8080\"");
    } else {
      c.web.listen = listen;
    }
  }
  t.String("root", c.web.root);
  t.Finish();
}

void ReadMeter(TableReader& root, Config& c, Issues& issues) {
  TableReader t(root.Table("meter"), "meter", issues);
  MeterConfig& m = c.meter;
  t.String("port", m.port);
  int baud = m.baud;
  if (t.Int("baud", baud, 1, 1000000)) {
    static constexpr int kBauds[] = {1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200};
    bool standard = false;
    for (int b : kBauds) standard |= b == baud;
    if (standard) {
      m.baud = baud;
    } else {
      t.Issue(*t.Node("baud"), "baud",
              std::to_string(baud) + " is not a standard rate (the PR-650 uses 9600)");
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
  t.Int("overhead_ms", m.overhead_ms, 0, 60000);
  // The PR-650's integration range (S command: 10 … 6000 ms).
  t.Int("adaptive_reference_ms", m.adaptive_reference_ms, 10, 6000);
  t.Int("adaptive_dark_ms", m.adaptive_dark_ms, 10, 6000);
  t.Int("adaptive_sample_ms", m.adaptive_sample_ms, 10, 6000);
  if (const toml::table* q = t.Table("quality")) {
    for (const auto& [key, node] : *q) {
      const std::string code_text(key.str());
      const std::string path = "meter.quality." + code_text;
      if (code_text.empty() || code_text.size() > 2 ||
          code_text.find_first_not_of("0123456789") != std::string::npos) {
        issues.Add(key.source(), path, "is not a quality code; use the code's number 0 … 99");
        continue;
      }
      const int code = std::stoi(code_text);
      drivers::pr650::QualityRule rule;
      std::string action;
      if (node.is_string()) {
        action = node.as_string()->get();
      } else if (node.is_table()) {
        TableReader r(node.as_table(), path, issues);
        if (!r.String("action", action)) {
          issues.Add(node.source(), path + ".action",
                     "missing; give one of " + std::string(kQualityActionNames));
        }
        r.Bool("accept_flagged_when_exhausted", rule.accept_flagged_when_exhausted);
        r.Finish();
      } else {
        issues.Add(node.source(), path,
                   std::string("must be an action name or a table, not ") + TypeName(node.type()));
        continue;
      }
      if (action.empty()) continue;
      const std::optional<drivers::pr650::QualityAction> parsed =
          drivers::pr650::ParseQualityAction(action);
      if (!parsed) {
        issues.Add(node.source(), path, "\"" + action + "\" is not one of " + kQualityActionNames);
        continue;
      }
      rule.action = *parsed;
      m.quality_overrides[code] = rule;
    }
  }
  t.Finish();
}

void ReadAxis(TableReader& axes, std::string_view name, AxisSettings& a, bool* present_given,
              Issues& issues) {
  const std::string path = "stage.axes." + std::string(name);
  const toml::table* table = axes.Table(name);
  TableReader t(table, path, issues);
  *present_given = t.Bool("present", a.present);
  t.Int("unit_id", a.unit_id, 1, 247);
  t.Double("counts_per_degree", a.counts_per_degree, 0, 1e7, /*lo_open=*/true);
  t.Double("zero_offset_deg", a.zero_offset_deg, -360, 360);
  double sign = a.sign;
  if (t.Double("sign", sign, -1, 1)) {
    if (sign == 1 || sign == -1) {
      a.sign = sign;
    } else {
      t.Issue(*t.Node("sign"), "sign", "must be 1 or -1, not " + Num(sign));
    }
  }
  const bool has_min = t.Double("min_deg", a.min_deg, -720, 720);
  const bool has_max = t.Double("max_deg", a.max_deg, -720, 720);
  if ((has_min || has_max) && a.min_deg >= a.max_deg) {
    t.Issue(
        *t.Node(has_max ? "max_deg" : "min_deg"), has_max ? "max_deg" : "min_deg",
        "travel [" + Num(a.min_deg) + ", " + Num(a.max_deg) + "] is empty; give min_deg < max_deg");
  }
  t.Double("speed_deg_s", a.speed_deg_s, 0, 360, /*lo_open=*/true);
  t.Finish();
}

void ReadStage(TableReader& root, Config& c, Issues& issues) {
  const toml::table* table = root.Table("stage");
  TableReader t(table, "stage", issues);
  StageConfig& s = c.stage;
  t.OneOf("transport", s.transport, {"tcp", "rtu"});
  std::string address;
  if (t.String("address", address)) {
    std::string reason;
    if (!SplitHostPort(address, 1, s.host, s.port, reason)) {
      t.Issue(*t.Node("address"), "address", reason + "; give e.g. \"192.168.1.50:502\"");
    }
  }
  t.String("device", s.device);
  int baud = s.baud;
  if (t.Int("baud", baud, 1200, 1000000)) s.baud = baud;
  std::string parity;
  if (t.OneOf("parity", parity, {"N", "E", "O"})) s.parity = parity[0];
  t.OneOf("profile", s.profile, {"az", "leadshine", "moons"});
  if (t.String("profile_file", s.profile_file)) {
    if (t.Node("profile") != nullptr) {
      t.Issue(*t.Node("profile_file"), "profile_file",
              "given with profile; keep one: profile names a built-in map, profile_file a file");
    }
  }
  t.Int("response_timeout_ms", s.response_timeout_ms, 10, 60000);
  t.Int("busy_window_ms", s.busy_window_ms, 0, 600000);
  t.Int("reconnect_max_ms", s.reconnect_max_ms, 100, 300000);
  t.Bool("detector_arm_motorized", s.detector_arm_motorized);
  if (s.transport == "rtu" && s.device.empty()) {
    issues.Add(table ? table->source() : toml::source_region{}, "stage.device",
               "missing; transport \"rtu\" needs the serial device, e.g. \"/dev/ttyUSB1\"");
  }

  const toml::table* axes_table = t.Table("axes");
  TableReader axes(axes_table, "stage.axes", issues);
  bool given[4] = {};
  // A motorized detector arm is the δ axis; δ is present exactly when the arm is motorized.
  s.delta.present = s.detector_arm_motorized;
  ReadAxis(axes, "alpha", s.alpha, &given[0], issues);
  ReadAxis(axes, "beta", s.beta, &given[1], issues);
  ReadAxis(axes, "gamma", s.gamma, &given[2], issues);
  ReadAxis(axes, "delta", s.delta, &given[3], issues);
  axes.Finish();
  const toml::source_region where = axes_table ? axes_table->source() : toml::source_region{};
  if (given[3] && s.delta.present != s.detector_arm_motorized) {
    issues.Add(where, "stage.axes.delta.present",
               std::string(s.delta.present ? "true" : "false") +
                   " contradicts stage.detector_arm_motorized = " +
                   (s.detector_arm_motorized ? "true" : "false") +
                   "; the δ axis is the motorized detector arm");
  }
  if (!s.alpha.present || !s.beta.present) {
    issues.Add(where, !s.alpha.present ? "stage.axes.alpha.present" : "stage.axes.beta.present",
               "must be true: the α and β stages are what the sample-rotation method turns");
  }
  std::map<int, std::string> units;
  const std::pair<const char*, const AxisSettings*> all[] = {
      {"alpha", &s.alpha}, {"beta", &s.beta}, {"gamma", &s.gamma}, {"delta", &s.delta}};
  for (const auto& [name, axis] : all) {
    if (!axis->present) continue;
    auto [it, inserted] = units.emplace(axis->unit_id, name);
    if (!inserted) {
      const toml::node* at = axes_table ? (*axes_table)[name]["unit_id"].node() : nullptr;
      issues.Add(at ? at->source() : where, "stage.axes." + std::string(name) + ".unit_id",
                 std::to_string(axis->unit_id) + " is also the unit id of " + it->second +
                     "; every axis needs its own Modbus unit");
    }
  }
  t.Finish();
}

void ReadAuth(TableReader& root, Config& c, Issues& issues) {
  TableReader t(root.Table("auth"), "auth", issues);
  if (const toml::array* tokens = t.Array("tokens")) {
    std::set<std::string> names;
    std::set<std::string> secrets;
    for (std::size_t i = 0; i < tokens->size(); ++i) {
      const toml::node& n = *tokens->get(i);
      const std::string path = "auth.tokens[" + std::to_string(i) + "]";
      if (!n.is_table()) {
        issues.Add(n.source(), path, "must be a table with name, token and role");
        continue;
      }
      TableReader r(n.as_table(), path, issues);
      TokenConfig tok;
      if (!r.String("name", tok.name)) {
        if (!r.Node("name")) issues.Add(n.source(), path + ".name", "missing; name the client");
      } else if (!names.insert(tok.name).second) {
        r.Issue(*r.Node("name"), "name", "\"" + tok.name + "\" is used by another token");
      }
      if (!r.String("token", tok.token)) {
        if (!r.Node("token")) issues.Add(n.source(), path + ".token", "missing; give the secret");
      } else if (tok.token.size() < kMinTokenLength) {
        r.Issue(*r.Node("token"), "token",
                "is " + std::to_string(tok.token.size()) + " characters; give at least " +
                    std::to_string(kMinTokenLength) + " (e.g. openssl rand -hex 24)");
      } else if (!secrets.insert(tok.token).second) {
        r.Issue(*r.Node("token"), "token", "is the same secret as another token's");
      }
      std::string role;
      if (r.OneOf("role", role, {"operator", "analyst"})) {
        tok.role = role == "operator" ? Role::kOperator : Role::kAnalyst;
      } else if (!r.Node("role")) {
        issues.Add(n.source(), path + ".role", "missing; give \"operator\" or \"analyst\"");
      }
      r.Finish();
      c.tokens.push_back(std::move(tok));
    }
  }
  t.Finish();
}

}  // namespace

const char* RoleName(Role role) {
  return role == Role::kOperator ? "operator" : "analyst";
}

Result<Config> ParseConfig(std::string_view toml_text, std::string_view source) {
  if (toml_text.size() > kMaxConfigBytes) {
    return ConfigurationError("config " + std::string(source) + ": " +
                              std::to_string(toml_text.size()) + " bytes, more than the " +
                              std::to_string(kMaxConfigBytes) + "-byte cap");
  }
  toml::table doc;
  try {
    doc = toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    return ConfigurationError("config " + std::string(source) + ": line " +
                              std::to_string(e.source().begin.line) + ", column " +
                              std::to_string(e.source().begin.column) +
                              ": not valid TOML: " + std::string(e.description()));
  } catch (const std::exception& e) {
    return ConfigurationError("config " + std::string(source) + ": cannot parse: " + e.what());
  }

  Config c;
  Issues issues;
  TableReader root(&doc, "", issues);
  ReadServer(root, c, issues);
  {
    TableReader t(root.Table("storage"), "storage", issues);
    t.String("database", c.storage.database);
    t.Finish();
  }
  ReadMeter(root, c, issues);
  ReadStage(root, c, issues);
  {
    TableReader t(root.Table("sample"), "sample", issues);
    t.Double("white_reflectance", c.sample.white_reflectance, 0, 1, /*lo_open=*/true);
    t.Finish();
  }
  {
    TableReader t(root.Table("rig"), "rig", issues);
    t.String("name", c.rig.name);
    t.Finish();
  }
  if (const toml::table* archive = root.Table("archive"); archive != nullptr) {
    TableReader t(archive, "archive", issues);
    if (!t.String("credentials", c.archive.credentials) && !t.Node("credentials")) {
      issues.Add(archive->source(), "archive.credentials",
                 "missing; give the path of a file holding the archive's libpq conninfo");
    }
    t.Int("batch_readings", c.archive.batch_readings, 1, 10000);
    t.Int("retry_ms", c.archive.retry_ms, 10, 600000);
    t.Finish();
  }
  ReadAuth(root, c, issues);
  {
    TableReader t(root.Table("log"), "log", issues);
    t.OneOf("level", c.log.level, {"trace", "debug", "info", "warn", "error", "critical", "off"});
    t.Finish();
  }
  ReadWeb(root, c, issues);
  root.Finish();
  if (!issues.empty()) return ConfigurationError(issues.Join(source));
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
  // The D5 report is ~1,730 bytes; 10 bits per byte on the wire (8N1).
  rig.meter_transfer_s = 1730.0 * 10.0 / config.meter.baud;
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
  // stage_poll_s keeps RigDescription's default: the stage driver's poll_interval, which the
  // configuration does not set (tests/config checks they agree).
  return rig;
}

}  // namespace brdf::daemon
