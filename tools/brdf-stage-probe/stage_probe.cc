#include "tools/brdf-stage-probe/stage_probe.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace brdf::tools::stage_probe {

namespace {

using drivers::stage::DecodeSigned;
using drivers::stage::DecodeStatus;
using drivers::stage::DecodeUnsigned;
using drivers::stage::RegisterField;
using drivers::stage::RegisterProfile;
using drivers::stage::WordOrder;

// A feedback position at least this far from 0 is beyond any stage's travel at the counts per
// revolution drives use (65,536 counts is several turns at 10,000 counts/rev).
constexpr std::int64_t kImplausibleCounts = 65536;

WordOrder Other(WordOrder o) {
  return o == WordOrder::kHighFirst ? WordOrder::kLowFirst : WordOrder::kHighFirst;
}

const char* OrderKey(WordOrder o) {
  return o == WordOrder::kHighFirst ? "high_first" : "low_first";
}
const char* OrderWords(WordOrder o) {
  return o == WordOrder::kHighFirst ? "upper word first" : "lower word first";
}

std::string Hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", v);
  return buf;
}

std::uint32_t KnownBits(const drivers::stage::StatusBits& b) {
  return b.ready | b.alarm | b.busy | b.moving | b.in_position;
}

// +1: evidence for the profile's order, −1: for the other one, 0: none.
int StatusEvidence(std::span<const std::uint16_t> regs, const RegisterProfile& p) {
  if (regs.size() != 2) return 0;
  const std::uint32_t known = KnownBits(p.status_bits);
  const bool as_profile = (DecodeUnsigned(regs, p.word_order) & known) != 0;
  const bool as_other = (DecodeUnsigned(regs, Other(p.word_order)) & known) != 0;
  if (as_profile && !as_other) return 1;
  if (as_other && !as_profile) return -1;
  return 0;
}

int PositionEvidence(std::span<const std::uint16_t> regs, const RegisterProfile& p) {
  if (regs.size() != 2) return 0;
  const auto far = [](std::int32_t v) { return std::llabs(v) >= kImplausibleCounts; };
  const bool profile_far = far(DecodeSigned(regs, p.word_order));
  const bool other_far = far(DecodeSigned(regs, Other(p.word_order)));
  if (profile_far && !other_far) return -1;
  if (other_far && !profile_far) return 1;
  return 0;
}

Result<std::vector<std::uint16_t>> Read(drivers::stage::ModbusBus& bus, int unit,
                                        const RegisterField& f, const CallContext& ctx) {
  return bus.ReadRegisters(unit, f.address, f.words, ctx);
}

AxisProbe ProbeUnit(drivers::stage::ModbusBus& bus, int unit, const ProbeOptions& o,
                    const CallContext& ctx) {
  const RegisterProfile& p = o.profile;
  AxisProbe a;
  a.unit_id = unit;
  auto status = Read(bus, unit, p.status, ctx);
  if (!status.ok()) {
    a.error = "status word " + Hex(p.status.address) + ": " + status.status().message();
    return a;
  }
  auto position = Read(bus, unit, p.feedback_position, ctx);
  if (!position.ok()) {
    a.error = "feedback position " + Hex(p.feedback_position.address) + ": " +
              position.status().message();
    return a;
  }
  a.answered = true;
  a.word_order = JudgeWordOrder(*status, *position, p);
  // Decode in the order the drive uses, so that the rest of the report is about the drive.
  const WordOrder order =
      a.word_order == WordOrderVerdict::kSwapped ? Other(p.word_order) : p.word_order;
  a.status_word = DecodeUnsigned(*status, order);
  a.flags = DecodeStatus(a.status_word, p.status_bits);
  a.position_counts = DecodeSigned(*position, order);
  if (p.alarm_code.present()) {
    auto alarm = Read(bus, unit, p.alarm_code, ctx);
    if (alarm.ok()) {
      a.alarm_code = static_cast<std::int32_t>(DecodeUnsigned(*alarm, order));
    } else {
      a.findings.push_back("the alarm code register " + Hex(p.alarm_code.address) +
                           " cannot be read (" + alarm.status().message() +
                           "): check alarm_code in the profile against the drive's manual");
    }
  }

  if (a.word_order == WordOrderVerdict::kSwapped) {
    a.findings.push_back(
        std::string("word order: the drive answers ") + OrderWords(order) + ", the profile '" +
        p.name + "' says " + OrderKey(p.word_order) + ". Set the drive's word-order parameter to " +
        OrderWords(p.word_order) + ", or set word_order = \"" + OrderKey(order) +
        "\" in a copy of the profile file and point [stage] profile_file at it; until then every "
        "move is refused (exception 03/04) or goes to the wrong place");
  }
  if (a.flags.alarm) {
    a.findings.push_back(
        "alarm present (code " +
        (a.alarm_code ? Hex(static_cast<std::uint32_t>(*a.alarm_code)) : std::string("unknown")) +
        "): remove the cause (drive display or alarm log), then reset the alarm "
        "before a session");
  } else if (p.status_bits.ready != 0 && !a.flags.ready) {
    a.findings.push_back("READY (" + Hex(p.status_bits.ready) +
                         ") is clear: the drive will not start a move (motor not excited, STOP "
                         "held, or a setting being applied); if it is ready on its display, "
                         "check status_bits.ready against the drive's output assignment");
  }
  if (a.flags.moving) a.findings.push_back("the axis is moving; probe again when it stands");
  return a;
}

}  // namespace

const char* WordOrderVerdictName(WordOrderVerdict v) {
  switch (v) {
    case WordOrderVerdict::kMatches:
      return "matches the profile";
    case WordOrderVerdict::kSwapped:
      return "SWAPPED against the profile";
    case WordOrderVerdict::kUndecided:
      return "undecided (no set status bit and position near 0: move the axis and probe again)";
    case WordOrderVerdict::kNotApplicable:
      return "not applicable (no 32-bit status or position register)";
  }
  return "?";
}

WordOrderVerdict JudgeWordOrder(std::span<const std::uint16_t> status_regs,
                                std::span<const std::uint16_t> position_regs,
                                const RegisterProfile& profile) {
  if (status_regs.size() != 2 && position_regs.size() != 2) {
    return WordOrderVerdict::kNotApplicable;
  }
  const int s = StatusEvidence(status_regs, profile);
  const int q = PositionEvidence(position_regs, profile);
  if ((s < 0 && q <= 0) || (q < 0 && s == 0)) return WordOrderVerdict::kSwapped;
  if ((s > 0 && q >= 0) || (q > 0 && s == 0)) return WordOrderVerdict::kMatches;
  return WordOrderVerdict::kUndecided;
}

bool ProbeReport::ok() const {
  for (const auto& a : axes) {
    if (!a.answered || !a.findings.empty()) return false;
  }
  return !axes.empty();
}

Result<ProbeReport> ProbeStage(const ProbeOptions& options, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(drivers::stage::ValidateBus(0, options.bus));
  BRDF_RETURN_IF_ERROR(drivers::stage::ValidateProfile(options.profile));
  ProbeReport report;
  report.bus = drivers::stage::DescribeBus(options.bus);
  report.profile = options.profile_label;
  drivers::stage::ModbusBus bus(options.bus);
  BRDF_RETURN_IF_ERROR(bus.Open(ctx));
  for (int unit : options.unit_ids) report.axes.push_back(ProbeUnit(bus, unit, options, ctx));
  bus.Close();
  return report;
}

std::string FormatReport(const ProbeReport& report, const ProbeOptions& options) {
  const RegisterProfile& p = options.profile;
  std::ostringstream out;
  out << "stage on " << report.bus << ", profile " << report.profile << " ('" << p.name << "'"
      << (p.verified_against_hardware ? "" : ", not verified against a drive") << ")\n";
  if (!p.ramp.unit.empty()) {
    out << "  ramps: the profile writes acceleration " << p.ramp.acceleration << " and "
        << "deceleration " << p.ramp.deceleration << " " << p.ramp.unit
        << " (a drive whose ramp unit is a setting must be set to " << p.ramp.unit << ")\n";
  }
  for (const auto& a : report.axes) {
    out << "unit " << a.unit_id << ": ";
    if (!a.answered) {
      out << "NO ANSWER: " << a.error << "\n";
      continue;
    }
    out << "status " << Hex(a.status_word) << " (" << (a.flags.ready ? "ready" : "not ready")
        << (a.flags.alarm ? ", ALARM" : "") << (a.flags.moving ? ", moving" : "")
        << (a.flags.in_position ? ", in position" : "") << "), position " << a.position_counts
        << " counts ("
        << drivers::stage::CountsToDegrees(a.position_counts, options.counts_per_degree, 0) << "°)";
    if (a.alarm_code) out << ", alarm code " << Hex(static_cast<std::uint32_t>(*a.alarm_code));
    out << "\n  word order: " << WordOrderVerdictName(a.word_order) << "\n";
    for (const auto& f : a.findings) out << "  MISMATCH: " << f << "\n";
  }
  out << (report.ok() ? "OK: every unit answered and fits the profile\n"
                      : "NOT OK: fix the mismatches above before starting a session\n");
  return out.str();
}

}  // namespace brdf::tools::stage_probe
