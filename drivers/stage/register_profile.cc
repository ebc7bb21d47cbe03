#include "drivers/stage/register_profile.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "drivers/stage/modbus_codec.h"
#include "drivers/stage/profile_file.h"

namespace brdf::drivers::stage {

namespace {

// Holding registers a single FC16 may write (Modbus application protocol limit).
constexpr int kMaxWriteRegisters = 123;

std::string Hex(unsigned value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", value);
  return buf;
}

class ProfileChecker {
 public:
  explicit ProfileChecker(const RegisterProfile& p)
      : name_(p.name.empty() ? std::string("(unnamed)") : p.name) {}

  Status Fail(const std::string& field, const std::string& problem) const {
    return ConfigurationError("stage profile '" + name_ + "' field '" + field + "': " + problem +
                              "; fix the stage register profile");
  }

  // `required` fields need 1 or 2 words; optional ones may also have 0 (absent).
  Status CheckField(const std::string& field, const RegisterField& f, bool required) const {
    if (f.words < (required ? 1 : 0) || f.words > 2) {
      return Fail(field + ".words", std::string("must be ") + (required ? "1 or 2" : "0, 1 or 2") +
                                        ", got " + std::to_string(f.words));
    }
    if (f.end() > 0x10000) {
      return Fail(field + ".address", "register " + Hex(f.address) + " plus " +
                                          std::to_string(f.words) +
                                          " words runs past the end of the register space");
    }
    return Status::Ok();
  }

  Status CheckValue(const std::string& field, std::int64_t value, const RegisterField& f,
                    bool is_signed) const {
    if (!FitsField(value, f.words, is_signed)) {
      return Fail(field, "value " + std::to_string(value) + " does not fit " +
                             std::to_string(f.words) + " register(s)");
    }
    return Status::Ok();
  }

  Status CheckCommand(const std::string& field, const CommandAction& c,
                      const RegisterProfile& p) const {
    switch (c.kind) {
      case CommandAction::Kind::kNone:
        return Status::Ok();
      case CommandAction::Kind::kPulseBits:
        if (!p.input_command.present()) {
          return Fail(field, "pulses bits of input_command, but input_command has no register");
        }
        if (c.value == 0) return Fail(field + ".value", "the bits to pulse are 0");
        return CheckValue(field + ".value", c.value, p.input_command, false);
      case CommandAction::Kind::kWriteValue:
        BRDF_RETURN_IF_ERROR(CheckField(field, c.field, true));
        return CheckValue(field + ".value", c.value, c.field, false);
    }
    return Fail(field + ".kind", "unknown command kind");
  }

 private:
  std::string name_;
};

struct NamedField {
  const char* name;
  RegisterField field;
};

// The fields written by the block FC16 (the trigger only when it is part of the block).
std::vector<NamedField> BlockFields(const RegisterProfile& p) {
  std::vector<NamedField> fields;
  if (p.operation_type.present()) fields.push_back({"operation_type", p.operation_type});
  fields.push_back({"position", p.position});
  fields.push_back({"speed", p.speed});
  for (const auto& c : p.block_constants) fields.push_back({"block_constants", c.field});
  if (p.trigger_style == TriggerStyle::kTriggerInBlock) fields.push_back({"trigger", p.trigger});
  return fields;
}

}  // namespace

RegisterProfile RegisterProfile::AzDefault() {
  static const RegisterProfile kProfile = BuiltinProfileOrDie("az");  // parsed once
  return kProfile;
}
RegisterProfile RegisterProfile::Leadshine() {
  static const RegisterProfile kProfile = BuiltinProfileOrDie("leadshine");  // parsed once
  return kProfile;
}
RegisterProfile RegisterProfile::Moons() {
  static const RegisterProfile kProfile = BuiltinProfileOrDie("moons");  // parsed once
  return kProfile;
}

BlockSpan OperationBlockSpan(const RegisterProfile& profile) {
  int end = profile.block_start;
  for (const auto& f : BlockFields(profile)) end = std::max(end, f.field.end());
  return BlockSpan{profile.block_start, end - profile.block_start};
}

Status ValidateProfile(const RegisterProfile& p) {
  const ProfileChecker check(p);
  BRDF_RETURN_IF_ERROR(check.CheckField("operation_type", p.operation_type, false));
  BRDF_RETURN_IF_ERROR(check.CheckField("position", p.position, true));
  BRDF_RETURN_IF_ERROR(check.CheckField("speed", p.speed, true));
  BRDF_RETURN_IF_ERROR(check.CheckField("trigger", p.trigger, true));
  BRDF_RETURN_IF_ERROR(check.CheckField("input_command", p.input_command, false));
  BRDF_RETURN_IF_ERROR(check.CheckField("status", p.status, true));
  BRDF_RETURN_IF_ERROR(check.CheckField("alarm_code", p.alarm_code, false));
  BRDF_RETURN_IF_ERROR(check.CheckField("feedback_position", p.feedback_position, true));
  for (const auto& c : p.block_constants) {
    BRDF_RETURN_IF_ERROR(check.CheckField("block_constants[" + c.what + "]", c.field, true));
    BRDF_RETURN_IF_ERROR(check.CheckValue("block_constants[" + c.what + "].value", c.value, c.field,
                                          c.field.words == 2));
  }
  if (p.operation_type.present()) {
    BRDF_RETURN_IF_ERROR(
        check.CheckValue("absolute_type", p.absolute_type, p.operation_type, false));
  }
  BRDF_RETURN_IF_ERROR(
      check.CheckValue("trigger_value", p.trigger_value, p.trigger, p.trigger.words == 2));
  if (!std::isfinite(p.speed_scale) || p.speed_scale <= 0) {
    return check.Fail("speed_scale", "must be a positive number");
  }

  // The block: every field inside [block_start, block_start + 123), none overlapping.
  auto fields = BlockFields(p);
  for (const auto& f : fields) {
    if (f.field.address < p.block_start) {
      return check.Fail(std::string(f.name) + ".address",
                        "register " + Hex(f.field.address) + " lies before block_start " +
                            Hex(p.block_start) + "; the block is written with one FC16");
    }
  }
  const BlockSpan span = OperationBlockSpan(p);
  if (span.count > kMaxWriteRegisters) {
    return check.Fail("block_start", "the operation block spans " + std::to_string(span.count) +
                                         " registers; one FC16 writes at most 123");
  }
  std::sort(fields.begin(), fields.end(), [](const NamedField& a, const NamedField& b) {
    return a.field.address < b.field.address;
  });
  for (std::size_t i = 1; i < fields.size(); ++i) {
    if (fields[i].field.address < fields[i - 1].field.end()) {
      return check.Fail(std::string(fields[i].name) + ".address",
                        "register " + Hex(fields[i].field.address) + " overlaps " +
                            fields[i - 1].name + " at " + Hex(fields[i - 1].field.address));
    }
  }

  BRDF_RETURN_IF_ERROR(check.CheckCommand("home", p.home, p));
  BRDF_RETURN_IF_ERROR(check.CheckCommand("stop", p.stop, p));
  BRDF_RETURN_IF_ERROR(check.CheckCommand("alarm_reset", p.alarm_reset, p));
  if (p.stop.kind == CommandAction::Kind::kNone) {
    return check.Fail("stop", "a stage must be stoppable (abort, pause immediate)");
  }

  const std::uint32_t status_max = p.status.words == 1 ? 0xFFFFu : 0xFFFFFFFFu;
  const std::pair<const char*, std::uint32_t> masks[] = {
      {"status_bits.ready", p.status_bits.ready},
      {"status_bits.alarm", p.status_bits.alarm},
      {"status_bits.busy", p.status_bits.busy},
      {"status_bits.moving", p.status_bits.moving},
      {"status_bits.in_position", p.status_bits.in_position}};
  for (const auto& [field, mask] : masks) {
    if ((mask & ~status_max) != 0) {
      return check.Fail(field, "mask " + Hex(mask) + " has bits outside the 16-bit status word");
    }
  }
  if (p.status_bits.moving == 0) {
    return check.Fail("status_bits.moving", "is 0; the driver needs MOVE to know a move ended");
  }
  if (p.status_bits.alarm == 0) {
    return check.Fail("status_bits.alarm", "is 0; the driver needs ALM-A to report alarms");
  }
  return Status::Ok();
}

Status ValidateAxis(Axis axis, const AxisConfig& c, const RegisterProfile& profile) {
  if (!c.present) return Status::Ok();
  auto fail = [&](const std::string& field, const std::string& problem) {
    return ConfigurationError(std::string("stage axis ") + AxisName(axis) + " field '" + field +
                              "': " + problem + "; fix the stage axis in the configuration");
  };
  if (c.bus < 0) return fail("bus", "must be 0 or more, got " + std::to_string(c.bus));
  if (c.unit_id < 1 || c.unit_id > 247) {
    return fail("unit_id", "must be 1–247, got " + std::to_string(c.unit_id));
  }
  if (!std::isfinite(c.counts_per_degree) || c.counts_per_degree <= 0) {
    return fail("counts_per_degree", "must be a positive number");
  }
  if (!std::isfinite(c.min_deg) || !std::isfinite(c.max_deg) || c.min_deg >= c.max_deg) {
    return fail("min_deg/max_deg", "limits must be finite with min < max, got " +
                                       std::to_string(c.min_deg) + " and " +
                                       std::to_string(c.max_deg));
  }
  if (!std::isfinite(c.speed_deg_s) || c.speed_deg_s <= 0) {
    return fail("speed_deg_s", "must be a positive number");
  }
  for (const auto& [field, deg] :
       {std::pair{"min_deg", c.min_deg}, std::pair{"max_deg", c.max_deg}}) {
    auto counts = DegreesToCounts(deg, c.counts_per_degree, c.zero_offset_counts);
    if (!counts.ok() || !FitsField(*counts, profile.position.words, true)) {
      return fail(field, "limit " + std::to_string(deg) +
                             "° does not fit the position register once converted to counts");
    }
  }
  auto speed = SpeedToRegister(c.speed_deg_s, c.counts_per_degree, profile.speed_scale);
  if (!speed.ok() || *speed <= 0 || !FitsField(*speed, profile.speed.words, false)) {
    return fail("speed_deg_s", "speed " + std::to_string(c.speed_deg_s) +
                                   "°/s does not give a usable value for the speed register");
  }
  return Status::Ok();
}

}  // namespace brdf::drivers::stage
