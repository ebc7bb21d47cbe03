#include "drivers/stage/profile_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

#include "drivers/stage/builtin_profiles.h"
#include "drivers/stage/modbus_codec.h"

namespace brdf::drivers::stage {

namespace {

constexpr std::size_t kMaxProfileBytes = 256 * 1024;

const char* TypeName(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number with a fraction";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date or time";
  }
}

// Reads one profile document. The first problem wins: later reads become no-ops, and Finish()
// returns it, naming the file, the line and the key.
class ProfileReader {
 public:
  explicit ProfileReader(std::string source) : source_(std::move(source)) {}

  bool failed() const { return !error_.empty(); }
  Status status() const { return failed() ? ConfigurationError(error_) : Status::Ok(); }

  void Fail(const toml::node* at, const std::string& key, const std::string& problem) {
    if (failed()) return;
    error_ = "stage profile file " + source_ + ": ";
    if (at != nullptr && at->source().begin.line > 0) {
      error_ += "line " + std::to_string(at->source().begin.line) + ": ";
    }
    error_ += "key '" + key + "': " + problem +
              "; fix the key in the file (the shipped profiles in share/brdfd/stage-profiles/, "
              "e.g. az.toml, show every key)";
  }

  // Refuses keys of `table` that are not in `known` (a typo must not fall back to a default).
  void OnlyKnown(const toml::table& table, const std::string& path,
                 std::initializer_list<std::string_view> known) {
    for (const auto& [k, v] : table) {
      if (std::find(known.begin(), known.end(), k.str()) == known.end()) {
        std::string list;
        for (auto n : known) list += (list.empty() ? "" : ", ") + std::string(n);
        Fail(&v, Join(path, k.str()), "unknown key (known here: " + list + ")");
      }
    }
  }

  static std::string Join(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
  }

  const toml::node* Get(const toml::table& t, const std::string& path, std::string_view key,
                        bool required) {
    const toml::node* n = t.get(key);
    if (n == nullptr && required) Fail(&t, Join(path, key), "missing");
    return n;
  }

  const toml::table* Table(const toml::table& t, const std::string& path, std::string_view key,
                           bool required) {
    const toml::node* n = Get(t, path, key, required);
    if (n == nullptr) return nullptr;
    if (!n->is_table()) {
      Fail(n, Join(path, key),
           std::string("must be a table such as { address = 0x0058, words = 2 }, got ") +
               TypeName(*n));
      return nullptr;
    }
    return n->as_table();
  }

  std::optional<std::int64_t> Int(const toml::table& t, const std::string& path,
                                  std::string_view key, bool required, std::int64_t lo,
                                  std::int64_t hi) {
    const toml::node* n = Get(t, path, key, required);
    if (n == nullptr || failed()) return std::nullopt;
    if (!n->is_integer()) {
      Fail(n, Join(path, key), std::string("must be an integer, got ") + TypeName(*n));
      return std::nullopt;
    }
    const std::int64_t v = n->as_integer()->get();
    if (v < lo || v > hi) {
      Fail(n, Join(path, key),
           "must be " + std::to_string(lo) + "–" + std::to_string(hi) + ", got " +
               std::to_string(v));
      return std::nullopt;
    }
    return v;
  }

  std::optional<double> Number(const toml::table& t, const std::string& path, std::string_view key,
                               bool required) {
    const toml::node* n = Get(t, path, key, required);
    if (n == nullptr || failed()) return std::nullopt;
    if (!n->is_number()) {
      Fail(n, Join(path, key), std::string("must be a number, got ") + TypeName(*n));
      return std::nullopt;
    }
    const double v = n->is_integer() ? static_cast<double>(n->as_integer()->get())
                                     : n->as_floating_point()->get();
    if (!std::isfinite(v)) {
      Fail(n, Join(path, key), "must be a finite number");
      return std::nullopt;
    }
    return v;
  }

  std::optional<std::string> String(const toml::table& t, const std::string& path,
                                    std::string_view key, bool required) {
    const toml::node* n = Get(t, path, key, required);
    if (n == nullptr || failed()) return std::nullopt;
    if (!n->is_string()) {
      Fail(n, Join(path, key), std::string("must be a string, got ") + TypeName(*n));
      return std::nullopt;
    }
    return n->as_string()->get();
  }

  std::optional<bool> Bool(const toml::table& t, const std::string& path, std::string_view key) {
    const toml::node* n = Get(t, path, key, false);
    if (n == nullptr || failed()) return std::nullopt;
    if (!n->is_boolean()) {
      Fail(n, Join(path, key), std::string("must be true or false, got ") + TypeName(*n));
      return std::nullopt;
    }
    return n->as_boolean()->get();
  }

  // One of `choices`; the index of the match.
  std::optional<std::size_t> OneOf(const toml::table& t, const std::string& path,
                                   std::string_view key, bool required,
                                   std::initializer_list<std::string_view> choices) {
    auto s = String(t, path, key, required);
    if (!s) return std::nullopt;
    std::size_t i = 0;
    std::string list;
    for (auto c : choices) {
      if (*s == c) return i;
      list += (list.empty() ? "\"" : ", \"") + std::string(c) + "\"";
      ++i;
    }
    Fail(t.get(key), Join(path, key), "\"" + *s + "\" is not one of " + list);
    return std::nullopt;
  }

  // A register table: { address, words }.
  RegisterField Field(const toml::table& t, const std::string& path, std::string_view key,
                      bool required) {
    const toml::table* f = Table(t, path, key, required);
    if (f == nullptr) return {};
    const std::string p = Join(path, key);
    OnlyKnown(*f, p, {"address", "words"});
    RegisterField out;
    if (auto a = Int(*f, p, "address", true, 0, 0xFFFF))
      out.address = static_cast<std::uint16_t>(*a);
    if (auto w = Int(*f, p, "words", true, 1, 2)) out.words = static_cast<int>(*w);
    return out;
  }

 private:
  std::string source_;
  std::string error_;
};

std::string Trimmed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

CommandAction ReadCommand(ProfileReader& r, const toml::table& root, std::string_view key) {
  const toml::table* t = r.Table(root, "", key, true);
  CommandAction c;
  if (t == nullptr) return c;
  const std::string p(key);
  r.OnlyKnown(*t, p, {"kind", "address", "words", "value"});
  auto kind = r.OneOf(*t, p, "kind", true, {"none", "pulse_bits", "write_value"});
  if (!kind) return c;
  if (*kind == 0) return c;
  if (auto v = r.Int(*t, p, "value", true, 0, 0xFFFFFFFF)) c.value = static_cast<std::uint32_t>(*v);
  if (*kind == 1) {
    c.kind = CommandAction::Kind::kPulseBits;
    return c;
  }
  c.kind = CommandAction::Kind::kWriteValue;
  if (auto a = r.Int(*t, p, "address", true, 0, 0xFFFF))
    c.field.address = static_cast<std::uint16_t>(*a);
  c.field.words = 1;
  if (auto w = r.Int(*t, p, "words", false, 1, 2)) c.field.words = static_cast<int>(*w);
  return c;
}

void ReadRamp(ProfileReader& r, const toml::table& root, RegisterProfile& p) {
  const toml::table* t = r.Table(root, "", "ramp", true);
  if (t == nullptr) return;
  r.OnlyKnown(*t, "ramp",
              {"unit", "per_unit", "acceleration", "deceleration", "acceleration_register",
               "deceleration_register"});
  if (auto u = r.String(*t, "ramp", "unit", true)) {
    if (u->empty()) r.Fail(t->get("unit"), "ramp.unit", "is empty; give the drive's ramp unit");
    p.ramp.unit = *u;
  }
  if (auto k = r.Number(*t, "ramp", "per_unit", true)) {
    if (*k <= 0) r.Fail(t->get("per_unit"), "ramp.per_unit", "must be positive");
    p.ramp.per_unit = *k;
  }
  const std::pair<const char*, double*> rates[] = {{"acceleration", &p.ramp.acceleration},
                                                   {"deceleration", &p.ramp.deceleration}};
  for (const auto& [what, value] : rates) {
    const RegisterField reg = r.Field(*t, "ramp", std::string(what) + "_register", true);
    auto v = r.Number(*t, "ramp", what, true);
    if (!v || r.failed()) return;
    const std::string key = std::string("ramp.") + what;
    if (*v < 0) {
      r.Fail(t->get(what), key, "must be 0 or more (0: the drive's own immediate change)");
      return;
    }
    *value = *v;
    const double counts = std::round(*v * p.ramp.per_unit);
    if (counts > 4294967295.0 || !FitsField(static_cast<std::int64_t>(counts), reg.words, false)) {
      r.Fail(t->get(what), key,
             Trimmed(*v) + " " + p.ramp.unit + " × per_unit " + Trimmed(p.ramp.per_unit) + " = " +
                 Trimmed(counts) + " does not fit " + std::to_string(reg.words) +
                 " register(s); lower it or check ramp.unit and ramp.per_unit");
      return;
    }
    p.block_constants.push_back(
        BlockConstant{reg, static_cast<std::int32_t>(static_cast<std::uint32_t>(counts)),
                      std::string(what) + " (" + Trimmed(*v) + " " + p.ramp.unit + ")"});
  }
}

void ReadBlockConstants(ProfileReader& r, const toml::table& root, RegisterProfile& p) {
  const toml::node* n = root.get("block_constants");
  if (n == nullptr) return;
  const toml::array* list = n->as_array();
  if (list == nullptr) {
    r.Fail(n, "block_constants",
           "must be an array of tables ([[block_constants]] with what, address, words, value)");
    return;
  }
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string path = "block_constants[" + std::to_string(i) + "]";
    const toml::table* t = list->get(i)->as_table();
    if (t == nullptr) {
      r.Fail(list->get(i), path, "must be a table with what, address, words and value");
      return;
    }
    r.OnlyKnown(*t, path, {"what", "address", "words", "value"});
    BlockConstant c;
    if (auto w = r.String(*t, path, "what", true)) c.what = *w;
    if (auto a = r.Int(*t, path, "address", true, 0, 0xFFFF)) {
      c.field.address = static_cast<std::uint16_t>(*a);
    }
    if (auto w = r.Int(*t, path, "words", true, 1, 2)) c.field.words = static_cast<int>(*w);
    if (auto v = r.Int(*t, path, "value", true, INT32_MIN, UINT32_MAX)) {
      c.value = static_cast<std::int32_t>(static_cast<std::uint32_t>(*v));
    }
    if (r.failed()) return;
    p.block_constants.push_back(std::move(c));
  }
}

void ReadTrigger(ProfileReader& r, const toml::table& root, RegisterProfile& p) {
  const toml::table* t = r.Table(root, "", "trigger", true);
  if (t == nullptr) return;
  r.OnlyKnown(*t, "trigger", {"style", "address", "words", "value"});
  if (auto s = r.OneOf(*t, "trigger", "style", true, {"in_block", "write_value", "opcode"})) {
    p.trigger_style = *s == 0   ? TriggerStyle::kTriggerInBlock
                      : *s == 1 ? TriggerStyle::kWriteValueToRegister
                                : TriggerStyle::kOpcodeRegister;
  }
  if (auto a = r.Int(*t, "trigger", "address", true, 0, 0xFFFF)) {
    p.trigger.address = static_cast<std::uint16_t>(*a);
  }
  if (auto w = r.Int(*t, "trigger", "words", true, 1, 2)) p.trigger.words = static_cast<int>(*w);
  if (auto v = r.Int(*t, "trigger", "value", true, INT32_MIN, UINT32_MAX)) {
    p.trigger_value = static_cast<std::int32_t>(static_cast<std::uint32_t>(*v));
  }
}

void ReadStatusBits(ProfileReader& r, const toml::table& root, RegisterProfile& p) {
  const toml::table* t = r.Table(root, "", "status_bits", true);
  if (t == nullptr) return;
  r.OnlyKnown(*t, "status_bits", {"ready", "alarm", "busy", "moving", "in_position"});
  const std::pair<const char*, std::uint32_t*> masks[] = {
      {"ready", &p.status_bits.ready},
      {"alarm", &p.status_bits.alarm},
      {"busy", &p.status_bits.busy},
      {"moving", &p.status_bits.moving},
      {"in_position", &p.status_bits.in_position}};
  for (const auto& [key, mask] : masks) {
    const bool required = std::string_view(key) == "moving" || std::string_view(key) == "alarm";
    if (auto v = r.Int(*t, "status_bits", key, required, 0, 0xFFFFFFFF)) {
      *mask = static_cast<std::uint32_t>(*v);
    }
  }
}

}  // namespace

Result<RegisterProfile> ParseProfileText(std::string_view text, const std::string& source) {
  if (text.size() > kMaxProfileBytes) {
    return ConfigurationError("stage profile file " + source + ": " + std::to_string(text.size()) +
                              " bytes, more than a profile's " + std::to_string(kMaxProfileBytes) +
                              "-byte cap; is it the right file?");
  }
  toml::table doc;
  try {
    doc = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return ConfigurationError(
        "stage profile file " + source + ": line " + std::to_string(e.source().begin.line) +
        ", column " + std::to_string(e.source().begin.column) +
        ": not valid TOML: " + std::string(e.description()) + "; fix the file");
  } catch (const std::exception& e) {
    return ConfigurationError("stage profile file " + source + ": cannot parse: " + e.what());
  }

  ProfileReader r(source);
  RegisterProfile p;
  r.OnlyKnown(doc, "", {"name",          "drive",
                        "source",        "verified_against_hardware",
                        "word_order",    "block_start",
                        "absolute_type", "operation_type",
                        "position",      "speed",
                        "speed_scale",   "block_constants",
                        "ramp",          "trigger",
                        "input_command", "home",
                        "stop",          "alarm_reset",
                        "status",        "status_bits",
                        "alarm_code",    "feedback_position"});
  if (auto v = r.String(doc, "", "name", true)) p.name = *v;
  if (auto v = r.String(doc, "", "drive", false)) p.drive = *v;
  if (auto v = r.String(doc, "", "source", true)) p.source = *v;
  if (auto v = r.Bool(doc, "", "verified_against_hardware")) p.verified_against_hardware = *v;
  if (auto w = r.OneOf(doc, "", "word_order", true, {"high_first", "low_first"})) {
    p.word_order = *w == 0 ? WordOrder::kHighFirst : WordOrder::kLowFirst;
  }
  if (auto v = r.Int(doc, "", "block_start", true, 0, 0xFFFF)) {
    p.block_start = static_cast<std::uint16_t>(*v);
  }
  p.operation_type = r.Field(doc, "", "operation_type", false);
  if (auto v = r.Int(doc, "", "absolute_type", p.operation_type.present(), 0, 0xFFFFFFFF)) {
    p.absolute_type = static_cast<std::int32_t>(static_cast<std::uint32_t>(*v));
  }
  p.position = r.Field(doc, "", "position", true);
  p.speed = r.Field(doc, "", "speed", true);
  if (auto v = r.Number(doc, "", "speed_scale", true)) p.speed_scale = *v;
  ReadBlockConstants(r, doc, p);
  ReadRamp(r, doc, p);
  ReadTrigger(r, doc, p);
  p.input_command = r.Field(doc, "", "input_command", false);
  p.home = ReadCommand(r, doc, "home");
  p.stop = ReadCommand(r, doc, "stop");
  p.alarm_reset = ReadCommand(r, doc, "alarm_reset");
  p.status = r.Field(doc, "", "status", true);
  ReadStatusBits(r, doc, p);
  p.alarm_code = r.Field(doc, "", "alarm_code", false);
  p.feedback_position = r.Field(doc, "", "feedback_position", true);
  BRDF_RETURN_IF_ERROR(r.status());

  std::stable_sort(p.block_constants.begin(), p.block_constants.end(),
                   [](const BlockConstant& a, const BlockConstant& b) {
                     return a.field.address < b.field.address;
                   });
  if (Status st = ValidateProfile(p); !st.ok()) {
    return ConfigurationError("stage profile file " + source + ": " + st.message());
  }
  return p;
}

Result<RegisterProfile> LoadProfileFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return ConfigurationError("stage profile file " + path +
                              ": cannot be read; check [stage] profile_file and the file's "
                              "permissions (copy one of share/brdfd/stage-profiles/*.toml)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return ParseProfileText(text.str(), path);
}

std::vector<std::string> BuiltinProfileNames() {
  std::vector<std::string> names;
  for (const auto& f : BuiltinProfileFiles()) names.emplace_back(f.name);
  return names;
}

std::string_view BuiltinProfileText(std::string_view name) {
  for (const auto& f : BuiltinProfileFiles()) {
    if (f.name == name) return f.text;
  }
  return {};
}

Result<RegisterProfile> BuiltinProfile(std::string_view name) {
  const std::string_view text = BuiltinProfileText(name);
  if (text.empty()) {
    std::string known;
    for (const auto& n : BuiltinProfileNames()) known += (known.empty() ? "" : ", ") + n;
    return ConfigurationError("unknown stage register profile \"" + std::string(name) +
                              "\" (built in: " + known +
                              "); or give your own with [stage] profile_file");
  }
  return ParseProfileText(text, "built-in '" + std::string(name) + "' (deploy/stage-profiles/" +
                                    std::string(name) + ".toml)");
}

RegisterProfile BuiltinProfileOrDie(std::string_view name) {
  auto p = BuiltinProfile(name);
  if (!p.ok()) {
    std::fprintf(stderr, "brdfd: %s\n", p.status().message().c_str());
    std::abort();
  }
  return std::move(p).value();
}

}  // namespace brdf::drivers::stage
