#include "drivers/stage/axis_io.h"

#include <algorithm>
#include <span>
#include <utility>
#include <vector>

namespace brdf::drivers::stage {

namespace {

const char* WordOrderName(WordOrder order) {
  return order == WordOrder::kHighFirst ? "high_first" : "low_first";
}

// A write the drive refused with exception 02, 03 or 04 is most often a register profile that does
// not match the drive's settings: with the other word order every 32-bit value arrives with its
// halves swapped (a position or rate out of range, a data number that does not exist). Says so,
// naming the profile settings to check; other failures pass through unchanged.
Status ExplainRefusedWrite(const Status& st, const RegisterProfile& profile) {
  const bool refused =
      (st.code() == StatusCode::kConfigurationError || st.code() == StatusCode::kDeviceError) &&
      st.device_code() >= 2 && st.device_code() <= 4;
  if (!refused) return st;
  return Status(st.code(),
                st.message() +
                    ". The drive refused a write: this usually means the stage "
                    "profile '" +
                    profile.name +
                    "' does not match the drive's settings. Check the profile's word_order (\"" +
                    WordOrderName(profile.word_order) +
                    "\") against the drive's word-order parameter, then its register addresses "
                    "and the ramp values and unit (brdf-stage-check reads them from the drive)",
                st.device_code());
}

}  // namespace

AxisIo::AxisIo(Axis axis, AxisConfig config, const RegisterProfile& profile, ModbusBus& bus)
    : axis_(axis),
      config_(std::move(config)),
      profile_(profile),
      bus_(bus),
      name_(std::string("axis ") + AxisName(axis) + " (unit " + std::to_string(config_.unit_id) +
            " on " + bus.description() + ")") {}

double AxisIo::CountsToDeg(std::int32_t counts) const {
  return CountsToDegrees(counts, config_.counts_per_degree, config_.zero_offset_counts);
}

Result<std::vector<std::uint16_t>> AxisIo::Read(const RegisterField& field, const CallContext& ctx,
                                                BusPriority priority, const char* what) const {
  auto regs = bus_.ReadRegisters(config_.unit_id, field.address, field.words, ctx, priority);
  if (!regs.ok()) return regs.status().WithContext(name_ + ": reading " + what);
  return regs;
}

Result<DriveStatus> AxisIo::ReadStatus(const CallContext& ctx, BusPriority priority) const {
  const RegisterField& st = profile_.status;
  const RegisterField& al = profile_.alarm_code;
  std::vector<std::uint16_t> status_regs;
  std::vector<std::uint16_t> alarm_regs;
  const bool adjacent = al.present() && (st.end() == al.address || al.end() == st.address);
  if (adjacent) {
    const RegisterField both{std::min(st.address, al.address), st.words + al.words};
    BRDF_ASSIGN_OR_RETURN(auto regs, Read(both, ctx, priority, "status and alarm code"));
    const auto st_at = regs.begin() + (st.address - both.address);
    const auto al_at = regs.begin() + (al.address - both.address);
    status_regs.assign(st_at, st_at + st.words);
    alarm_regs.assign(al_at, al_at + al.words);
  } else {
    BRDF_ASSIGN_OR_RETURN(auto regs, Read(st, ctx, priority, "status"));
    status_regs = std::move(regs);
  }
  DriveStatus out;
  out.raw = DecodeUnsigned(status_regs, profile_.word_order);
  out.flags = DecodeStatus(out.raw, profile_.status_bits);
  if (out.flags.alarm && al.present()) {
    if (alarm_regs.empty()) {
      BRDF_ASSIGN_OR_RETURN(auto regs, Read(al, ctx, priority, "alarm code"));
      alarm_regs = std::move(regs);
    }
    out.alarm_code = static_cast<int>(DecodeUnsigned(alarm_regs, profile_.word_order));
  }
  return out;
}

Result<std::int32_t> AxisIo::ReadFeedbackCounts(const CallContext& ctx) const {
  BRDF_ASSIGN_OR_RETURN(
      auto regs, Read(profile_.feedback_position, ctx, BusPriority::kNormal, "feedback position"));
  return DecodeSigned(regs, profile_.word_order);
}

Result<double> AxisIo::ReadPositionDeg(const CallContext& ctx) const {
  BRDF_ASSIGN_OR_RETURN(auto counts, ReadFeedbackCounts(ctx));
  return CountsToDeg(counts);
}

Status AxisIo::StartMove(double target_deg, const CallContext& ctx) const {
  auto counts = DegreesToCounts(target_deg, config_.counts_per_degree, config_.zero_offset_counts);
  if (!counts.ok()) return counts.status().WithContext(name_ + ": target");
  auto speed =
      SpeedToRegister(config_.speed_deg_s, config_.counts_per_degree, profile_.speed_scale);
  if (!speed.ok()) return speed.status().WithContext(name_ + ": speed");

  const BlockSpan span = OperationBlockSpan(profile_);
  std::vector<std::uint16_t> block(static_cast<std::size_t>(span.count), 0);
  auto put = [&](const RegisterField& f, std::int32_t value) {
    EncodeField(value, f.words, profile_.word_order,
                std::span(block).subspan(static_cast<std::size_t>(f.address - span.start),
                                         static_cast<std::size_t>(f.words)));
  };
  for (const auto& c : profile_.block_constants) put(c.field, c.value);
  if (profile_.operation_type.present()) put(profile_.operation_type, profile_.absolute_type);
  put(profile_.position, *counts);
  put(profile_.speed, *speed);
  const bool trigger_in_block = profile_.trigger_style == TriggerStyle::kTriggerInBlock;
  if (trigger_in_block) put(profile_.trigger, profile_.trigger_value);

  Status st = bus_.WriteRegisters(config_.unit_id, span.start, std::move(block), ctx);
  if (!st.ok()) {
    return ExplainRefusedWrite(st, profile_).WithContext(name_ + ": writing the operation block");
  }
  if (trigger_in_block) return Status::Ok();

  std::vector<std::uint16_t> trigger(static_cast<std::size_t>(profile_.trigger.words), 0);
  EncodeField(profile_.trigger_value, profile_.trigger.words, profile_.word_order, trigger);
  st = bus_.WriteRegisters(config_.unit_id, profile_.trigger.address, std::move(trigger), ctx);
  if (!st.ok())
    return ExplainRefusedWrite(st, profile_).WithContext(name_ + ": writing the trigger");
  return Status::Ok();
}

Status AxisIo::SetCommand(const CommandAction& command, const char* command_name, bool on,
                          const CallContext& ctx, BusPriority priority) const {
  RegisterField field;
  std::uint32_t value = 0;
  switch (command.kind) {
    case CommandAction::Kind::kNone:
      return FailedPrecondition(name_ + ": the stage profile '" + profile_.name + "' has no " +
                                command_name + " command; do it at the drive");
    case CommandAction::Kind::kPulseBits:
      field = profile_.input_command;
      value = on ? command.value : 0;
      break;
    case CommandAction::Kind::kWriteValue:
      if (!on) return Status::Ok();
      field = command.field;
      value = command.value;
      break;
  }
  std::vector<std::uint16_t> regs(static_cast<std::size_t>(field.words), 0);
  EncodeField(static_cast<std::int32_t>(value), field.words, profile_.word_order, regs);
  Status st = bus_.WriteRegisters(config_.unit_id, field.address, std::move(regs), ctx, priority);
  if (!st.ok()) {
    return st.WithContext(name_ + ": " + (on ? "setting " : "clearing ") + command_name);
  }
  return Status::Ok();
}

}  // namespace brdf::drivers::stage
