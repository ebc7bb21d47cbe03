// brdf-stage-probe's work: connect to the stage's drives over Modbus TCP or RTU, read each axis's
// status word, alarm code and feedback position with a register profile, and say what does not
// fit the profile and what to set, before a session finds out mid-move.
//
// Reads only (FC03): the probe never writes a register, so it is safe on a drive that is
// holding a sample. Word order is judged from what the drive answers: a 32-bit status word whose
// known bits (the profile's status_bits) all sit in the wrong half, or a feedback position that is
// far outside any travel one way and small the other way, means the drive lays 32-bit values out
// the other way round. A drive at position 0 with no known status bit set gives no evidence
// either way and is reported as undecided.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/status.h"
#include "drivers/stage/modbus_bus.h"
#include "drivers/stage/modbus_codec.h"
#include "drivers/stage/register_profile.h"

namespace brdf::tools::stage_probe {

enum class WordOrderVerdict { kMatches, kSwapped, kUndecided, kNotApplicable };
const char* WordOrderVerdictName(WordOrderVerdict v);  // "matches", "swapped", ...

// Pure: judges the word order from the raw registers of the status word and the feedback
// position (each 1 or 2 registers, in address order) as the drive answered them.
WordOrderVerdict JudgeWordOrder(std::span<const std::uint16_t> status_regs,
                                std::span<const std::uint16_t> position_regs,
                                const drivers::stage::RegisterProfile& profile);

struct AxisProbe {
  int unit_id = 0;
  bool answered = false;
  std::string error;              // why the unit did not answer (when !answered)
  std::uint32_t status_word = 0;  // decoded in the profile's word order
  drivers::stage::StatusFlags flags;
  std::optional<std::int32_t> alarm_code;
  std::int32_t position_counts = 0;  // in the profile's word order
  WordOrderVerdict word_order = WordOrderVerdict::kUndecided;
  std::vector<std::string> findings;  // mismatches and what to set; empty: all fits
};

struct ProbeOptions {
  drivers::stage::BusConfig bus;
  drivers::stage::RegisterProfile profile;
  std::string profile_label;        // "built-in az", "file /etc/brdfd/stage.toml"
  std::vector<int> unit_ids{1, 2};  // the axes' Modbus unit ids
  double counts_per_degree = 10000.0 / 360.0;
};

struct ProbeReport {
  std::string bus;      // DescribeBus
  std::string profile;  // profile_label
  std::vector<AxisProbe> axes;
  // Every unit answered and nothing was found.
  bool ok() const;
};

// kDisconnected when the bus cannot be opened at all; a unit that does not answer is reported in
// its AxisProbe, not as an error.
Result<ProbeReport> ProbeStage(const ProbeOptions& options, const CallContext& ctx);

// The report as text for the lab, one block per unit, each finding with what to set.
std::string FormatReport(const ProbeReport& report, const ProbeOptions& options);

}  // namespace brdf::tools::stage_probe
