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

#include "core/toml/table_reader.h"
#include "drivers/stage/builtin_profiles.h"
#include "drivers/stage/modbus_codec.h"

namespace brdf::drivers::stage {

namespace {

using toml_keys::Empty;
using toml_keys::Problems;
using toml_keys::TableReader;

constexpr std::size_t kMaxProfileBytes = 256 * 1024;

// What a refused profile's message ends with.
constexpr const char* kAdvice =
    "fix the file (the shipped profiles in share/brdfd/stage-profiles/, e.g. az.toml, show every "
    "key)";

std::string Trimmed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A 32-bit register value given as 0 … 0xFFFFFFFF or as a negative int32.
std::int32_t RegisterValue(std::int64_t v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(v));
}

// A register table: { address, words }; absent (words 0) when not `required` and not given.
RegisterField ReadField(TableReader& parent, std::string_view key, bool required) {
  if (required && !parent.Require(key)) return {};
  TableReader f = parent.Sub(key, "a table such as { address = 0x0058, words = 2 }");
  if (f.table() == nullptr) return {};
  RegisterField out;
  if (f.Require("address")) f.Int("address", out.address, 0, 0xFFFF);
  if (f.Require("words")) f.Int("words", out.words, 1, 2);
  f.Finish();
  return out;
}

// home, stop, alarm_reset: { kind = "none" | "pulse_bits" | "write_value", value, address, words }.
CommandAction ReadCommandKeys(TableReader& t) {
  CommandAction c;
  std::size_t kind = 0;
  if (!t.Require("kind") || !t.OneOf("kind", kind, {"none", "pulse_bits", "write_value"})) return c;
  if (kind == 0) return c;
  std::int64_t value = 0;
  if (t.Require("value") && t.Int("value", value, 0, 0xFFFFFFFF)) {
    c.value = static_cast<std::uint32_t>(value);
  }
  if (kind == 1) {
    c.kind = CommandAction::Kind::kPulseBits;
    return c;
  }
  c.kind = CommandAction::Kind::kWriteValue;
  if (t.Require("address")) t.Int("address", c.field.address, 0, 0xFFFF);
  c.field.words = 1;
  t.Int("words", c.field.words, 1, 2);
  return c;
}

CommandAction ReadCommand(TableReader& root, std::string_view key) {
  if (!root.Require(key)) return {};
  TableReader t = root.Sub(key);
  if (t.table() == nullptr) return {};
  t.Allow({"kind", "address", "words", "value"});  // read only for the kinds that use them
  const CommandAction c = ReadCommandKeys(t);
  t.Finish();
  return c;
}

// ramp.acceleration or ramp.deceleration in ramp.unit, and its register, as a block constant;
// false when it cannot be (the problem noted).
bool ReadRampRate(TableReader& t, const Problems& problems, const char* what, double* value,
                  RegisterProfile& p) {
  const RegisterField reg = ReadField(t, std::string(what) + "_register", true);
  double v = 0;
  if (!t.Require(what) || !t.Double(what, v) || !problems.empty()) return false;
  if (v < 0) {
    t.Issue(what, "must be 0 or more (0: the drive's own immediate change)");
    return false;
  }
  *value = v;
  const double counts = std::round(v * p.ramp.per_unit);
  if (counts > 4294967295.0 || !FitsField(static_cast<std::int64_t>(counts), reg.words, false)) {
    t.Issue(what, Trimmed(v) + " " + p.ramp.unit + " × per_unit " + Trimmed(p.ramp.per_unit) +
                      " = " + Trimmed(counts) + " does not fit " + std::to_string(reg.words) +
                      " register(s); lower it or check ramp.unit and ramp.per_unit");
    return false;
  }
  p.block_constants.push_back(
      BlockConstant{reg, static_cast<std::int32_t>(static_cast<std::uint32_t>(counts)),
                    std::string(what) + " (" + Trimmed(v) + " " + p.ramp.unit + ")"});
  return true;
}

void ReadRamp(TableReader& root, const Problems& problems, RegisterProfile& p) {
  if (!root.Require("ramp")) return;
  TableReader t = root.Sub("ramp");
  if (t.table() == nullptr) return;
  // A rate is read once the ones before it are good (its counts depend on them).
  t.Allow({"unit", "per_unit", "acceleration", "deceleration", "acceleration_register",
           "deceleration_register"});
  if (t.Require("unit") && t.String("unit", p.ramp.unit, Empty::kAllowed) && p.ramp.unit.empty()) {
    t.Issue("unit", "is empty; give the drive's ramp unit");
  }
  if (t.Require("per_unit") && t.Double("per_unit", p.ramp.per_unit) && p.ramp.per_unit <= 0) {
    t.Issue("per_unit", "must be positive");
  }
  if (ReadRampRate(t, problems, "acceleration", &p.ramp.acceleration, p)) {
    ReadRampRate(t, problems, "deceleration", &p.ramp.deceleration, p);
  }
  t.Finish();
}

void ReadBlockConstants(TableReader& root, RegisterProfile& p) {
  root.ArrayOfTables("block_constants", "what, address, words and value",
                     [&p](TableReader& t, std::size_t) {
                       BlockConstant c;
                       if (t.Require("what")) t.String("what", c.what, Empty::kAllowed);
                       if (t.Require("address")) t.Int("address", c.field.address, 0, 0xFFFF);
                       if (t.Require("words")) t.Int("words", c.field.words, 1, 2);
                       std::int64_t value = 0;
                       if (t.Require("value") && t.Int("value", value, INT32_MIN, UINT32_MAX)) {
                         c.value = RegisterValue(value);
                       }
                       t.Finish();
                       p.block_constants.push_back(std::move(c));
                     });
}

void ReadTrigger(TableReader& root, RegisterProfile& p) {
  if (!root.Require("trigger")) return;
  TableReader t = root.Sub("trigger");
  if (t.table() == nullptr) return;
  std::size_t style = 0;
  if (t.Require("style") && t.OneOf("style", style, {"in_block", "write_value", "opcode"})) {
    p.trigger_style = style == 0   ? TriggerStyle::kTriggerInBlock
                      : style == 1 ? TriggerStyle::kWriteValueToRegister
                                   : TriggerStyle::kOpcodeRegister;
  }
  if (t.Require("address")) t.Int("address", p.trigger.address, 0, 0xFFFF);
  if (t.Require("words")) t.Int("words", p.trigger.words, 1, 2);
  std::int64_t value = 0;
  if (t.Require("value") && t.Int("value", value, INT32_MIN, UINT32_MAX)) {
    p.trigger_value = RegisterValue(value);
  }
  t.Finish();
}

void ReadStatusBits(TableReader& root, RegisterProfile& p) {
  if (!root.Require("status_bits")) return;
  TableReader t = root.Sub("status_bits");
  if (t.table() == nullptr) return;
  const std::pair<const char*, std::uint32_t*> masks[] = {
      {"ready", &p.status_bits.ready},
      {"alarm", &p.status_bits.alarm},
      {"busy", &p.status_bits.busy},
      {"moving", &p.status_bits.moving},
      {"in_position", &p.status_bits.in_position}};
  for (const auto& [key, mask] : masks) {
    const bool required = std::string_view(key) == "moving" || std::string_view(key) == "alarm";
    if (!required || t.Require(key)) t.Int(key, *mask, 0, 0xFFFFFFFF);
  }
  t.Finish();
}

// The keys of the document itself: names, word order, the operation block's fields.
void ReadBlock(TableReader& root, RegisterProfile& p) {
  if (root.Require("name")) root.String("name", p.name, Empty::kAllowed);
  root.String("drive", p.drive, Empty::kAllowed);
  if (root.Require("source")) root.String("source", p.source, Empty::kAllowed);
  root.Bool("verified_against_hardware", p.verified_against_hardware);
  std::size_t order = 0;
  if (root.Require("word_order") && root.OneOf("word_order", order, {"high_first", "low_first"})) {
    p.word_order = order == 0 ? WordOrder::kHighFirst : WordOrder::kLowFirst;
  }
  if (root.Require("block_start")) root.Int("block_start", p.block_start, 0, 0xFFFF);
  p.operation_type = ReadField(root, "operation_type", false);
  std::int64_t absolute_type = 0;
  if ((!p.operation_type.present() || root.Require("absolute_type")) &&
      root.Int("absolute_type", absolute_type, 0, 0xFFFFFFFF)) {
    p.absolute_type = RegisterValue(absolute_type);
  }
  p.position = ReadField(root, "position", true);
  p.speed = ReadField(root, "speed", true);
  if (root.Require("speed_scale")) root.Double("speed_scale", p.speed_scale);
}

}  // namespace

Result<RegisterProfile> ParseProfileText(std::string_view text, const std::string& source) {
  const std::string file = "stage profile file " + source;
  if (text.size() > kMaxProfileBytes) {
    return ConfigurationError(file + ": " + std::to_string(text.size()) +
                              " bytes, more than a profile's " + std::to_string(kMaxProfileBytes) +
                              "-byte cap; is it the right file?");
  }
  Problems problems(file, StatusCode::kConfigurationError, kAdvice);
  BRDF_ASSIGN_OR_RETURN(const toml::table doc, problems.Parse(text, source));
  TableReader root(problems, &doc);
  RegisterProfile p;
  ReadBlock(root, p);
  ReadBlockConstants(root, p);
  ReadRamp(root, problems, p);
  ReadTrigger(root, p);
  p.input_command = ReadField(root, "input_command", false);
  p.home = ReadCommand(root, "home");
  p.stop = ReadCommand(root, "stop");
  p.alarm_reset = ReadCommand(root, "alarm_reset");
  p.status = ReadField(root, "status", true);
  ReadStatusBits(root, p);
  p.alarm_code = ReadField(root, "alarm_code", false);
  p.feedback_position = ReadField(root, "feedback_position", true);
  root.Finish();
  BRDF_RETURN_IF_ERROR(problems.status());

  std::stable_sort(p.block_constants.begin(), p.block_constants.end(),
                   [](const BlockConstant& a, const BlockConstant& b) {
                     return a.field.address < b.field.address;
                   });
  if (Status st = ValidateProfile(p); !st.ok()) {
    return ConfigurationError(file + ": " + st.message());
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
