// How a rotation-stage drive looks on the Modbus bus, as pure configuration data: which holding
// registers hold the operation block, the status word, the alarm code and the feedback position,
// how a 32-bit value is split into two registers, how a move is triggered and how home, stop and
// alarm reset are commanded. Plus, per axis, the unit id and the conversion between degrees and
// the drive's counts.
//
// Addresses are PDU addresses (0-based). Vendor manuals number holding registers from 1 ("40125"
// is PDU address 124): subtract one when copying from a manual. See
// docs/stage-modbus.md for the default (AZ-like) map and the other two.
//
// Nothing here talks to a device; ValidateProfile / ValidateAxis reject a configuration that
// cannot work, naming the field, before the driver touches the bus.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"
#include "drivers/rotation_stage.h"

namespace brdf::drivers::stage {

// Order of the two 16-bit halves of a 32-bit value: kHighFirst puts the upper word at the lower
// address (Oriental Motor's "upper word first", the usual default).
enum class WordOrder { kHighFirst, kLowFirst };

// A value in the register space: `words` registers (1 = 16 bit, 2 = 32 bit) starting at PDU
// address `address`. words == 0 means the drive has no such register.
struct RegisterField {
  std::uint16_t address = 0;
  int words = 0;
  bool present() const { return words > 0; }
  // One past the last register.
  int end() const { return address + words; }
};

// How writing the operation block becomes motion.
enum class TriggerStyle {
  // AZ "direct data operation": the trigger register is part of the block; the single FC16 that
  // writes the block ends with the trigger word and starts the move.
  kTriggerInBlock,
  // Leadshine PR mode: write the block, then write `trigger_value` to `trigger` (0x6002 ← 0x0010).
  kWriteValueToRegister,
  // Moons'/Applied Motion: write the block (distance, velocity), then write the "feed to position"
  // opcode to the opcode register (`trigger`, PDU 124).
  kOpcodeRegister,
};

// A constant the driver writes with every operation block (acceleration, current, data number).
struct BlockConstant {
  RegisterField field;
  std::int32_t value = 0;
  std::string what;  // for messages: "start rate"
};

// How the driver commands home, stop or alarm reset.
struct CommandAction {
  enum class Kind {
    kNone,        // the drive has no such command on the bus
    kPulseBits,   // set `value` bits in the driver input command register, hold, then clear
    kWriteValue,  // write `value` to `field` (a command or opcode register)
  };
  Kind kind = Kind::kNone;
  RegisterField field;      // for kWriteValue; kPulseBits uses RegisterProfile::input_command
  std::uint32_t value = 0;  // bits to pulse, or the value to write
};

// Masks of the status word. A zero mask means the drive does not report that condition; a drive
// without an IN-POS bit is in position when it is neither moving nor in alarm.
struct StatusBits {
  std::uint32_t ready = 0;
  std::uint32_t alarm = 0;
  std::uint32_t busy = 0;
  std::uint32_t moving = 0;
  std::uint32_t in_position = 0;
};

// Acceleration and deceleration as the lab gives them: in the unit the drive is set to (the AZ's
// acceleration/deceleration unit parameter: kHz/s, s or ms/kHz), and how many register counts
// make one unit. The profile file's [ramp] turns them into two block constants.
struct RampSettings {
  std::string unit;     // "kHz/s", "ms/1000 rpm", ...; for messages and the probe's report
  double per_unit = 1;  // register counts per unit (AZ: 1000, the registers hold 0.001 kHz/s)
  double acceleration = 0;
  double deceleration = 0;
};

struct RegisterProfile {
  std::string name;
  std::string drive;   // which drive and mode the map is for
  std::string source;  // the manual tables it follows (docs/stage-modbus.md has the detail)
  // False for maps taken from manuals but never run against a drive: the daemon logs a warning.
  bool verified_against_hardware = false;
  WordOrder word_order = WordOrder::kHighFirst;

  // The operation block, written with one FC16 starting at block_start and covering every field
  // below that lies in it (gaps are written as 0).
  std::uint16_t block_start = 0;
  RegisterField operation_type;                // absent on drives whose trigger implies the type
  std::int32_t absolute_type = 1;              // value meaning "absolute position"
  RegisterField position;                      // target, in counts
  RegisterField speed;                         // in counts per second × speed_scale
  double speed_scale = 1.0;                    // register units per (count/s), e.g. rpm per count/s
  std::vector<BlockConstant> block_constants;  // sorted by address; includes the ramp's two
  RampSettings ramp;

  TriggerStyle trigger_style = TriggerStyle::kTriggerInBlock;
  RegisterField trigger;
  std::int32_t trigger_value = 1;

  // Driver input command register (level bits) for kPulseBits commands.
  RegisterField input_command;
  CommandAction home;
  CommandAction stop;
  CommandAction alarm_reset;

  RegisterField status;
  StatusBits status_bits;
  RegisterField alarm_code;         // absent: the alarm bit is reported with code 0
  RegisterField feedback_position;  // counts; sources disagree on the address, keep it configurable

  // The built-in profiles, parsed from the files shipped in deploy/stage-profiles/ (compiled into
  // the binary, profile_file.h). A built-in file that does not parse is a build defect: these
  // abort with the parser's message (tests/drivers_stage checks every shipped file loads).
  // The default: Oriental Motor AZ-like direct data operation (stage-modbus.md). Verified against
  // the reference map and the simulator.
  static RegisterProfile AzDefault();
  // Leadshine PR mode (target 0x6201/0x6202, trigger 0x6002 ← 0x0010, status 0x1003). Expressible,
  // NOT verified against hardware: check every address and bit against the drive's manual.
  static RegisterProfile Leadshine();
  // Moons'/Applied Motion (opcode register 124, 32-bit distance 30–31, status 1). Expressible, NOT
  // verified against hardware: check every address, bit and opcode against the drive's manual.
  static RegisterProfile Moons();
};

// The registers of the operation block write: [start, start + count).
struct BlockSpan {
  std::uint16_t start = 0;
  int count = 0;
};
// Span of the single FC16 that writes the block (through the trigger for kTriggerInBlock).
BlockSpan OperationBlockSpan(const RegisterProfile& profile);

// kConfigurationError naming the field ("stage profile 'az': status.words must be 1 or 2, got 3").
Status ValidateProfile(const RegisterProfile& profile);

// One axis of the stage on the bus.
struct AxisConfig {
  bool present = false;
  int bus = 0;                                 // index into the stage's buses
  int unit_id = 0;                             // Modbus unit (slave) id, 1–247
  double counts_per_degree = 10000.0 / 360.0;  // 10,000 counts per revolution
  std::int32_t zero_offset_counts = 0;         // counts read at 0°
  double min_deg = -180;                       // travel limits, inclusive
  double max_deg = 180;
  double speed_deg_s = 10;  // move speed
};

// kConfigurationError naming the axis and field. Checks that the limits and speed fit the
// registers of `profile` once converted to counts.
Status ValidateAxis(Axis axis, const AxisConfig& config, const RegisterProfile& profile);

}  // namespace brdf::drivers::stage
