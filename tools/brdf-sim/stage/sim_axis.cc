#include "tools/brdf-sim/stage/sim_axis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace brdf::sim {

using namespace sim_axis;  // NOLINT(google-build-using-namespace): this file's register names

namespace {

bool InBlock(std::uint32_t a) {
  return a >= kBlockStart && a < kBlockStart + kBlockWords;
}
bool InCommand(std::uint32_t a) {
  return a == kInputCommand || a == kInputCommand + 1u;
}
bool Readable(std::uint32_t a) {
  return InBlock(a) || InCommand(a) || (a >= kStatus && a <= kAlarmCode + 1u) || a == kFeedback ||
         a == kFeedback + 1u || a == kFeedbackAlt || a == kFeedbackAlt + 1u;
}

// The speed profile of a move of `distance` counts (>= 0) at `speed` with the given acceleration
// and deceleration (counts/s², +inf: at once): a trapezoid, or a triangle when the move is too
// short to reach the speed.
struct SpeedProfile {
  double peak = 0;    // counts/s
  double t_up = 0;    // s, ramping up
  double t_run = 0;   // s, at the peak speed
  double t_down = 0;  // s, ramping down
  double total() const { return t_up + t_run + t_down; }
};

SpeedProfile ProfileOf(double distance, double speed, double accel, double decel) {
  SpeedProfile p;
  if (distance <= 0 || speed <= 0) return p;
  p.peak = speed;
  if (speed * speed * (0.5 / accel + 0.5 / decel) > distance) {
    p.peak = std::sqrt(2 * distance / (1 / accel + 1 / decel));
  }
  p.t_up = p.peak / accel;
  p.t_down = p.peak / decel;
  p.t_run = std::max(0.0, (distance - 0.5 * p.peak * (p.t_up + p.t_down)) / p.peak);
  return p;
}

// Distance covered `t` seconds into that move.
double Travelled(double distance, double speed, double accel, double decel, double t) {
  const SpeedProfile p = ProfileOf(distance, speed, accel, decel);
  if (t <= 0 || p.peak <= 0) return 0;
  if (t < p.t_up) return 0.5 * accel * t * t;
  if (t < p.t_up + p.t_run) return 0.5 * p.peak * p.t_up + p.peak * (t - p.t_up);
  if (t < p.total()) return distance - 0.5 * decel * (p.total() - t) * (p.total() - t);
  return distance;
}

double MoveDuration(double distance, double speed, double accel, double decel) {
  return ProfileOf(distance, speed, accel, decel).total();
}

}  // namespace

bool SimAxis::HighWordFirst() const {
  return (config_.word_order == SimWordOrder::kHighFirst) != control_.modbus().swap_word_order;
}

std::int32_t SimAxis::Join(std::uint16_t first, std::uint16_t second) const {
  const bool high_first = HighWordFirst();
  const std::uint32_t high = high_first ? first : second;
  const std::uint32_t low = high_first ? second : first;
  return static_cast<std::int32_t>((high << 16) | low);
}

std::uint16_t SimAxis::WordOf(std::uint32_t value, std::uint32_t offset) const {
  const bool upper = (offset == 0) == HighWordFirst();
  return static_cast<std::uint16_t>(upper ? value >> 16 : value & 0xFFFFu);
}

SimAxis::SimAxis(SimAxisConfig config, SimControl& control, std::function<double()> now_s)
    : config_(std::move(config)),
      control_(control),
      now_s_(std::move(now_s)),
      block_(kBlockWords, 0) {
  motion_.start_counts =
      std::round(config_.initial_deg * config_.counts_per_degree) + config_.zero_offset_counts;
  motion_.start_s = now_s_();
}

void SimAxis::Advance(double now) const {
  Motion& m = motion_;
  if (!m.moving || m.stalled) return;
  const double distance = std::abs(m.target_counts - m.start_counts);
  const double end_s = m.start_s + MoveDuration(distance, m.speed, m.accel, m.decel);
  if (m.alarm_at_s >= 0 && now >= m.alarm_at_s && m.alarm_at_s < end_s) {
    m.start_counts = std::round(CountsAt(m.alarm_at_s));  // a drive rests on whole counts
    m.moving = false;
    m.alarm_at_s = -1;
    alarm_ = true;
    alarm_code_ = kAlarmMidMove;
    return;
  }
  if (now >= end_s) {
    m.start_counts = m.target_counts;
    m.moving = false;
    m.alarm_at_s = -1;
  }
}

double SimAxis::CountsAt(double now) const {
  const Motion& m = motion_;
  if (!m.moving || m.stalled) return m.start_counts;
  const double distance = m.target_counts - m.start_counts;
  const double travelled =
      Travelled(std::abs(distance), m.speed, m.accel, m.decel, std::max(0.0, now - m.start_s));
  if (travelled >= std::abs(distance)) return m.target_counts;
  return m.start_counts + std::copysign(travelled, distance);
}

double SimAxis::PositionDeg() const {
  const double now = now_s_();
  Advance(now);
  return (CountsAt(now) - config_.zero_offset_counts) / config_.counts_per_degree;
}

SimAxisSnapshot SimAxis::Snapshot() const {
  const double now = now_s_();
  Advance(now);
  SimAxisSnapshot s;
  const double counts = CountsAt(now);
  s.position_counts = static_cast<std::int32_t>(std::lround(counts));
  s.position_deg = (counts - config_.zero_offset_counts) / config_.counts_per_degree;
  s.moving = motion_.moving;
  s.alarm = alarm_;
  s.alarm_code = alarm_code_;
  s.in_position = !motion_.moving && !alarm_;
  s.moves_started = moves_started_;
  return s;
}

std::uint32_t SimAxis::StatusWord() const {
  std::uint32_t s = 0;
  if (motion_.moving) s |= kMove;
  if (alarm_) s |= kAlarm;
  if (!motion_.moving && !alarm_) s |= kReady | kInPos;
  return s;
}

std::uint16_t SimAxis::RegisterAt(std::uint16_t a, double now) const {
  if (InBlock(a)) return block_[a - kBlockStart];
  const auto feedback = static_cast<std::uint32_t>(std::lround(CountsAt(now)));
  switch (a) {
    case kInputCommand:
    case kInputCommand + 1:
      return WordOf(input_command_, a - kInputCommand);
    case kStatus:
    case kStatus + 1:
      return WordOf(StatusWord(), a - kStatus);
    case kAlarmCode:
    case kAlarmCode + 1:
      return WordOf(static_cast<std::uint32_t>(alarm_code_), a - kAlarmCode);
    case kFeedback:
    case kFeedback + 1:
      return WordOf(feedback, a - kFeedback);
    case kFeedbackAlt:
    case kFeedbackAlt + 1:
      return WordOf(feedback, a - kFeedbackAlt);
    default:
      return 0;
  }
}

std::uint8_t SimAxis::ReadRegisters(std::uint16_t address, std::uint16_t count,
                                    std::vector<std::uint16_t>& out) {
  for (std::uint32_t a = address; a < address + static_cast<std::uint32_t>(count); ++a) {
    if (!Readable(a)) return modbus::kIllegalDataAddress;
  }
  const double now = now_s_();
  Advance(now);
  out.clear();
  for (std::uint32_t a = address; a < address + static_cast<std::uint32_t>(count); ++a) {
    out.push_back(RegisterAt(static_cast<std::uint16_t>(a), now));
  }
  return 0;
}

std::int32_t SimAxis::BlockInt32(std::uint16_t address) const {
  return Join(block_[address - kBlockStart], block_[address - kBlockStart + 1]);
}

std::uint8_t SimAxis::CheckBlockStartable(std::span<const std::uint16_t> block) const {
  auto at = [&](std::uint16_t a) {
    return Join(block[a - kBlockStart], block[a - kBlockStart + 1]);
  };
  const std::int32_t type = at(kType);
  if (type != 1 && type != 2) return modbus::kIllegalDataValue;
  if (at(kSpeed) <= 0) return modbus::kIllegalDataValue;
  return 0;
}

std::uint8_t SimAxis::WriteRegisters(std::uint16_t address, std::span<const std::uint16_t> values) {
  const std::uint32_t end = address + static_cast<std::uint32_t>(values.size());
  for (std::uint32_t a = address; a < end; ++a) {
    if (!InBlock(a) && !InCommand(a)) return modbus::kIllegalDataAddress;
  }
  const double now = now_s_();
  Advance(now);

  if (InBlock(address)) {
    std::vector<std::uint16_t> block = block_;
    for (std::size_t i = 0; i < values.size(); ++i) block[address - kBlockStart + i] = values[i];
    const bool trigger_written = address <= kTrigger + 1u && end > kTrigger;
    const std::int32_t trigger =
        Join(block[kTrigger - kBlockStart], block[kTrigger - kBlockStart + 1]);
    if (trigger_written && trigger != 0) {
      if (trigger != 1) return modbus::kIllegalDataValue;
      if (const std::uint8_t ex = CheckBlockStartable(block); ex != 0) return ex;
      block[kTrigger - kBlockStart] = 0;  // the trigger reads 0 once applied
      block[kTrigger - kBlockStart + 1] = 0;
      block_ = std::move(block);
      StartOperation(now);
      return 0;
    }
    block_ = std::move(block);
    return 0;
  }

  // The driver input command: act on rising edges.
  std::uint16_t words[2] = {WordOf(input_command_, 0), WordOf(input_command_, 1)};
  for (std::size_t i = 0; i < values.size(); ++i) words[address + i - kInputCommand] = values[i];
  const auto command = static_cast<std::uint32_t>(Join(words[0], words[1]));
  const std::uint32_t rising = command & ~input_command_;
  input_command_ = command;
  if ((rising & kAlarmReset) != 0) {
    alarm_ = false;
    alarm_code_ = 0;
    if (motion_.stalled) StopNow(now);
  }
  if ((rising & kStop) != 0) StopNow(now);
  if ((rising & kZhome) != 0) StartHoming(now);
  if ((rising & kStart) != 0 && CheckBlockStartable(block_) == 0) StartOperation(now);
  return 0;
}

void SimAxis::StopNow(double now) {
  motion_.start_counts = std::round(CountsAt(now));
  motion_.start_s = now;
  motion_.moving = false;
  motion_.stalled = false;
  motion_.alarm_at_s = -1;
}

void SimAxis::StartOperation(double now) {
  if (alarm_ || (input_command_ & kStop) != 0) return;  // a drive in alarm or held stopped ignores
  const double from = std::round(CountsAt(now));
  const std::int32_t position = BlockInt32(kPosition);
  const double target = BlockInt32(kType) == 1 ? position : from + position;
  const double min_counts =
      std::round(config_.min_deg * config_.counts_per_degree) + config_.zero_offset_counts;
  const double max_counts =
      std::round(config_.max_deg * config_.counts_per_degree) + config_.zero_offset_counts;
  if (target < min_counts || target > max_counts) {
    StopNow(now);
    alarm_ = true;
    alarm_code_ = kAlarmOvertravel;
    return;
  }
  const double speed = BlockInt32(kSpeed);
  Begin(now, target, speed, RampAcceleration(kStartRate, speed), RampAcceleration(kStopRate, speed),
        true);
}

double SimAxis::RampAcceleration(std::uint16_t address, double speed) const {
  const double value = BlockInt32(address) * 0.001;  // registers hold thousandths of the unit
  if (value <= 0) return std::numeric_limits<double>::infinity();
  switch (config_.ramp_unit) {
    case SimRampUnit::kKhzPerSecond:
      return value * 1000;  // kHz/s = 1000 counts/s²
    case SimRampUnit::kSeconds:
      return speed / value;  // standstill to speed in `value` s
    case SimRampUnit::kMsPerKhz:
      return 1000 / (value * 0.001);  // 1 kHz in `value` ms
  }
  return std::numeric_limits<double>::infinity();
}

void SimAxis::StartHoming(double now) {
  if (alarm_ || (input_command_ & kStop) != 0) return;
  constexpr double kAtOnce = std::numeric_limits<double>::infinity();
  Begin(now, config_.zero_offset_counts,
        std::max(1.0, config_.home_speed_deg_s * config_.counts_per_degree), kAtOnce, kAtOnce,
        false);
}

void SimAxis::Begin(double now, double target_counts, double speed, double accel, double decel,
                    bool take_faults) {
  Motion m;
  m.start_counts = std::round(CountsAt(now));
  m.start_s = now;
  m.target_counts = target_counts;
  m.speed = speed;
  m.accel = accel;
  m.decel = decel;
  bool alarm_mid_move = false;
  if (take_faults) {
    control_.UpdateModbus([&](ModbusFaults& f) {
      alarm_mid_move = f.alarm_mid_move;
      m.stalled = f.stall;
      f.alarm_mid_move = false;
      f.stall = false;
    });
  }
  const double duration =
      MoveDuration(std::abs(target_counts - m.start_counts), speed, accel, decel);
  m.moving = duration > 0 || m.stalled;
  ++moves_started_;
  if (alarm_mid_move) {
    if (duration > 0) {
      m.alarm_at_s = now + duration / 2;
    } else {
      alarm_ = true;
      alarm_code_ = kAlarmMidMove;
      m.moving = false;
    }
  }
  motion_ = m;
}

}  // namespace brdf::sim
