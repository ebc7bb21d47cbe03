// One simulated stage drive (one axis, one unit id), modelled on an Oriental Motor AZ drive in
// "direct data operation" (docs/stage-modbus.md, profile `az`):
//
//   0x0058–0x0069  operation data block (data no., type, position, speed, start rate, stop rate,
//                  current, trigger, forwarding destination), 32-bit values in the drive's word
//                  order (SimAxisConfig::word_order: upper word first by default, as shipped);
//                  writing trigger = 1 applies the block and starts the move (type 1 absolute,
//                  2 incremental), then the trigger reads 0 again
//   0x007C–0x007D  driver input command: bit 3 START, 4 ZHOME, 5 STOP, 7 ALM-RST (acted on the
//                  rising edge; levels: STOP held refuses starts)
//   0x007E–0x007F  driver output status: bit 5 READY, 7 ALM-A, 8 SYS-BSY, 13 MOVE, 14 IN-POS
//   0x0080–0x0081  present alarm code (0x67 software overtravel, 0x30 the injected mid-move alarm)
//   0x00CC–0x00CD  feedback position (counts), mirrored at 0x0120–0x0121
//
// Any other address answers exception 02; a write outside the block and the input command too.
// Motion is computed from the simulator's clock when asked: the position ramps up at the block's
// starting rate to its speed (counts per simulated second), runs, and ramps down at the stopping
// rate onto the target (a triangle when the move is too short to reach the speed), MOVE set and
// IN-POS clear meanwhile. The rates are read in SimAxisConfig::ramp_unit; a rate of 0 (or homing,
// which runs at home_speed_deg_s) changes speed at once. A
// target outside the travel limits raises ALM-A (0x67) and does not move; an alarm stays until
// ALM-RST; no move starts while an alarm is set. Injected faults (SimControl::modbus()) armed when
// a move starts: an alarm half-way, or a stall that keeps MOVE set until STOP or ALM-RST.
//
// Not thread-safe: the owner (StageSimulator) serializes access.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "tools/brdf-sim/sim_shared.h"
#include "tools/brdf-sim/stage/pdu.h"

namespace brdf::sim {

// How a drive lays a 32-bit value over two registers (an AZ parameter, "upper word first" by
// default): kHighFirst puts the upper 16 bits at the lower address.
enum class SimWordOrder { kHighFirst, kLowFirst };

// The unit of the block's starting/changing rate and stopping deceleration (an AZ parameter; the
// registers hold the value in thousandths of it): kHz/s (the AZ default: 1,000,000 is
// 1,000 kHz/s, i.e. 10⁶ counts/s²), s (the time from standstill to the operating speed, or back)
// or ms/kHz (the time per kHz of speed change).
enum class SimRampUnit { kKhzPerSecond, kSeconds, kMsPerKhz };

struct SimAxisConfig {
  int unit_id = 1;
  SimWordOrder word_order = SimWordOrder::kHighFirst;
  SimRampUnit ramp_unit = SimRampUnit::kKhzPerSecond;
  bool present = true;
  double counts_per_degree = 10000.0 / 360.0;
  std::int32_t zero_offset_counts = 0;  // counts at 0°
  double min_deg = -180;                // the drive's software limits
  double max_deg = 180;
  double home_speed_deg_s = 20;  // ZHOME runs to 0° at this speed
  double initial_deg = 0;
};

// What a test or the CLI may want to see without going through Modbus.
struct SimAxisSnapshot {
  double position_deg = 0;
  std::int32_t position_counts = 0;
  bool moving = false;
  bool in_position = false;
  bool alarm = false;
  int alarm_code = 0;
  int moves_started = 0;  // triggers that started motion (including homing)
};

namespace sim_axis {
inline constexpr std::uint16_t kBlockStart = 0x0058;
inline constexpr std::uint16_t kBlockWords = 18;  // 0x0058–0x0069
inline constexpr std::uint16_t kType = 0x005A;
inline constexpr std::uint16_t kPosition = 0x005C;
inline constexpr std::uint16_t kSpeed = 0x005E;
inline constexpr std::uint16_t kStartRate = 0x0060;
inline constexpr std::uint16_t kStopRate = 0x0062;
inline constexpr std::uint16_t kTrigger = 0x0066;
inline constexpr std::uint16_t kInputCommand = 0x007C;
inline constexpr std::uint16_t kStatus = 0x007E;
inline constexpr std::uint16_t kAlarmCode = 0x0080;
inline constexpr std::uint16_t kFeedback = 0x00CC;
inline constexpr std::uint16_t kFeedbackAlt = 0x0120;

inline constexpr std::uint32_t kStart = 1u << 3;
inline constexpr std::uint32_t kZhome = 1u << 4;
inline constexpr std::uint32_t kStop = 1u << 5;
inline constexpr std::uint32_t kAlarmReset = 1u << 7;

inline constexpr std::uint32_t kReady = 1u << 5;
inline constexpr std::uint32_t kAlarm = 1u << 7;
inline constexpr std::uint32_t kSysBusy = 1u << 8;
inline constexpr std::uint32_t kMove = 1u << 13;
inline constexpr std::uint32_t kInPos = 1u << 14;

inline constexpr int kAlarmOvertravel = 0x67;
inline constexpr int kAlarmMidMove = 0x30;
}  // namespace sim_axis

class SimAxis final : public RegisterUnit {
 public:
  // `now_s` gives the simulated time in seconds (monotonic); `control` supplies the move faults.
  SimAxis(SimAxisConfig config, SimControl& control, std::function<double()> now_s);

  std::uint8_t ReadRegisters(std::uint16_t address, std::uint16_t count,
                             std::vector<std::uint16_t>& out) override;
  std::uint8_t WriteRegisters(std::uint16_t address,
                              std::span<const std::uint16_t> values) override;

  const SimAxisConfig& config() const { return config_; }
  double PositionDeg() const;
  SimAxisSnapshot Snapshot() const;

 private:
  struct Motion {
    double start_counts = 0;  // where the current segment started (or where the axis rests)
    double start_s = 0;
    double target_counts = 0;
    double speed = 0;  // counts per simulated second, > 0 while moving
    double accel = 0;  // counts/s² up to the speed and down from it; +inf: at once
    double decel = 0;
    bool moving = false;
    bool stalled = false;
    double alarm_at_s = -1;  // injected alarm time, < 0 = none
  };

  // Brings the motion up to `now` (finishes moves, raises the injected alarm).
  void Advance(double now) const;
  double CountsAt(double now) const;
  // The block's rate register at `address` as counts/s² for a move at `speed` (+inf for 0).
  double RampAcceleration(std::uint16_t address, double speed) const;
  std::uint32_t StatusWord() const;
  std::uint16_t RegisterAt(std::uint16_t address, double now) const;
  std::int32_t BlockInt32(std::uint16_t address) const;
  // The configured word order, or the other one while the control unit swaps it.
  bool HighWordFirst() const;
  // A 32-bit value from the registers at its lower and higher address, in the word order.
  std::int32_t Join(std::uint16_t lower_address_word, std::uint16_t higher_address_word) const;
  // The register at `offset` (0: lower address, 1: higher) of a 32-bit value, in the word order.
  std::uint16_t WordOf(std::uint32_t value, std::uint32_t offset) const;
  // Starts a move from the operation block; returns an exception code for a block that cannot
  // start (bad type or speed), 0 otherwise (an out-of-range target is an alarm, not an exception).
  std::uint8_t CheckBlockStartable(std::span<const std::uint16_t> block) const;
  void StartOperation(double now);
  void StartHoming(double now);
  void StopNow(double now);
  void Begin(double now, double target_counts, double speed, double accel, double decel,
             bool take_faults);

  SimAxisConfig config_;
  SimControl& control_;
  std::function<double()> now_s_;
  std::vector<std::uint16_t> block_;  // 0x0058–0x0069
  std::uint32_t input_command_ = 0;
  mutable Motion motion_;
  mutable bool alarm_ = false;
  mutable int alarm_code_ = 0;
  int moves_started_ = 0;
};

}  // namespace brdf::sim
