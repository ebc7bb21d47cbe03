// The stage simulator without a driver: RTU framing and CRC, the AZ-like register model of one
// drive (motion, alarms, commands), the control unit, and where injected faults fire.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "tools/brdf-sim/stage/control_map.h"
#include "tools/brdf-sim/stage/rtu_frame.h"
#include "tools/brdf-sim/stage/simulator.h"

namespace brdf::sim {
namespace {

using std::chrono::milliseconds;
namespace ax = sim_axis;
namespace cm = control_map;

std::vector<std::uint8_t> ReadPdu(std::uint16_t address, std::uint16_t count) {
  return {0x03, static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address),
          static_cast<std::uint8_t>(count >> 8), static_cast<std::uint8_t>(count)};
}

std::vector<std::uint8_t> WritePdu(std::uint16_t address, const std::vector<std::uint16_t>& v) {
  std::vector<std::uint8_t> pdu{
      0x10, static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address),
      0,    static_cast<std::uint8_t>(v.size()),     static_cast<std::uint8_t>(2 * v.size())};
  for (std::uint16_t r : v) {
    pdu.push_back(static_cast<std::uint8_t>(r >> 8));
    pdu.push_back(static_cast<std::uint8_t>(r));
  }
  return pdu;
}

std::vector<std::uint16_t> Regs(const std::vector<std::uint8_t>& reply) {
  std::vector<std::uint16_t> out;
  for (std::size_t i = 2; i + 1 < reply.size(); i += 2) {
    out.push_back(static_cast<std::uint16_t>((reply[i] << 8) | reply[i + 1]));
  }
  return out;
}

std::int32_t Int32(std::uint16_t high, std::uint16_t low) {
  return static_cast<std::int32_t>((static_cast<std::uint32_t>(high) << 16) | low);
}

// The AZ operation block from 0x0058 through the trigger, as the driver writes it.
std::vector<std::uint16_t> Block(std::int32_t type, std::int32_t position, std::int32_t speed,
                                 std::int32_t trigger = 1) {
  std::vector<std::uint16_t> b(16, 0);
  auto put = [&](std::uint16_t address, std::int32_t v) {
    b[address - 0x58] = static_cast<std::uint16_t>(static_cast<std::uint32_t>(v) >> 16);
    b[address - 0x58 + 1] = static_cast<std::uint16_t>(static_cast<std::uint32_t>(v) & 0xFFFF);
  };
  put(ax::kType, type);
  put(ax::kPosition, position);
  put(ax::kSpeed, speed);
  put(ax::kTrigger, trigger);
  return b;
}

class SimModel : public ::testing::Test {
 protected:
  SimModel() {
    StageSimConfig c;
    c.time_scale.factor = 20;
    c.serve_tcp = false;
    c.serve_rtu = false;
    c.axes[1].counts_per_degree = 100;  // β: 100 counts/°, ±180°
    sim_ = std::make_unique<StageSimulator>(c, control_);
  }

  std::vector<std::uint8_t> Ask(std::uint8_t unit, const std::vector<std::uint8_t>& pdu,
                                StageTransport t = StageTransport::kTcp) {
    StageReply r = sim_->HandleForTest(unit, pdu, t);
    EXPECT_EQ(r.kind, StageReply::Kind::kReply);
    return r.pdu;
  }
  std::uint32_t Status(std::uint8_t unit) {
    const auto regs = Regs(Ask(unit, ReadPdu(ax::kStatus, 2)));
    return static_cast<std::uint32_t>(Int32(regs[0], regs[1]));
  }
  std::int32_t Feedback(std::uint8_t unit) {
    const auto regs = Regs(Ask(unit, ReadPdu(ax::kFeedback, 2)));
    return Int32(regs[0], regs[1]);
  }
  void Command(std::uint8_t unit, std::uint32_t bits) {
    Ask(unit, WritePdu(ax::kInputCommand, {static_cast<std::uint16_t>(bits >> 16),
                                           static_cast<std::uint16_t>(bits & 0xFFFF)}));
  }

  SimControl control_;
  std::unique_ptr<StageSimulator> sim_;
};

TEST(ModbusCrc16, MatchesTheSpecificationExample) {
  const std::vector<std::uint8_t> frame{0x01, 0x03, 0x00, 0x00, 0x00, 0x0A};
  EXPECT_EQ(ModbusCrc16(frame), 0xCDC5);  // on the wire: C5 CD
  std::vector<std::uint8_t> with = frame;
  AppendCrc(with);
  EXPECT_EQ(with[6], 0xC5);
  EXPECT_EQ(with[7], 0xCD);
}

TEST(RtuFrameSplitter, SplitsBackToBackFramesForDifferentSlaves) {
  std::vector<std::uint8_t> a{0x01, 0x03, 0x00, 0x7E, 0x00, 0x04};
  std::vector<std::uint8_t> b{0x02, 0x10, 0x00, 0x7C, 0x00, 0x02, 0x04, 0x00, 0x00, 0x00, 0x20};
  AppendCrc(a);
  AppendCrc(b);
  std::vector<std::uint8_t> stream{0x55, 0xAA};  // line noise first
  stream.insert(stream.end(), a.begin(), a.end());
  stream.insert(stream.end(), b.begin(), b.end());
  RtuFrameSplitter splitter;
  const auto now = std::chrono::steady_clock::now();
  // Delivered in two arbitrary chunks.
  splitter.Feed(std::span(stream).first(9), now);
  splitter.Feed(std::span(stream).subspan(9), now);
  auto first = splitter.Next();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(*first, std::vector<std::uint8_t>(a.begin(), a.end() - 2));
  auto second = splitter.Next();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(*second, std::vector<std::uint8_t>(b.begin(), b.end() - 2));
  EXPECT_FALSE(splitter.Next().has_value());
  EXPECT_EQ(splitter.dropped_bytes(), 2);
}

TEST(RtuFrameSplitter, RejectsABadCrcAndDropsHalfFramesAfterAGap) {
  std::vector<std::uint8_t> bad{0x01, 0x03, 0x00, 0x7E, 0x00, 0x02};
  AppendCrc(bad);
  bad.back() ^= 0xFF;
  RtuFrameSplitter splitter(milliseconds(50));
  const auto t0 = std::chrono::steady_clock::now();
  splitter.Feed(bad, t0);
  EXPECT_FALSE(splitter.Next().has_value());
  EXPECT_GE(splitter.crc_errors(), 1);

  std::vector<std::uint8_t> good{0x03, 0x03, 0x00, 0xCC, 0x00, 0x02};
  AppendCrc(good);
  RtuFrameSplitter halves(milliseconds(50));
  halves.Feed(std::span(good).first(4), t0);
  EXPECT_FALSE(halves.Next().has_value());
  // The rest arrives after a long silence: the first half is gone, so is the frame.
  halves.Feed(std::span(good).subspan(4), t0 + milliseconds(200));
  EXPECT_FALSE(halves.Next().has_value());
  // A complete frame after that is found again.
  halves.Feed(good, t0 + milliseconds(400));
  auto frame = halves.Next();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ((*frame)[0], 0x03);
}

TEST_F(SimModel, AnIdleAxisIsReadyAndInPosition) {
  const std::uint32_t s = Status(1);
  EXPECT_NE(s & ax::kReady, 0u);
  EXPECT_NE(s & ax::kInPos, 0u);
  EXPECT_EQ(s & ax::kMove, 0u);
  EXPECT_EQ(Feedback(1), 0);
}

TEST_F(SimModel, AMoveRunsAtTheBlockSpeedWithMoveSetUntilItArrives) {
  // β: 100 counts/°; 60° at 30°/s = 2 simulated s = 100 real ms at ×20.
  Ask(2, WritePdu(0x58, Block(1, 6000, 3000)));
  std::uint32_t s = Status(2);
  EXPECT_NE(s & ax::kMove, 0u);
  EXPECT_EQ(s & ax::kInPos, 0u);
  std::this_thread::sleep_for(milliseconds(40));
  const std::int32_t midway = Feedback(2);
  EXPECT_GT(midway, 0);
  EXPECT_LT(midway, 6000);
  EXPECT_NEAR(sim_->LivePose().beta, midway / 100.0, 5.0);
  std::this_thread::sleep_for(milliseconds(120));
  s = Status(2);
  EXPECT_EQ(s & ax::kMove, 0u);
  EXPECT_NE(s & ax::kInPos, 0u);
  EXPECT_EQ(Feedback(2), 6000);
  EXPECT_DOUBLE_EQ(sim_->LivePose().beta, 60.0);
  // The trigger reads 0 once applied; the block keeps the target.
  const auto block = Regs(Ask(2, ReadPdu(0x58, 18)));
  EXPECT_EQ(Int32(block[ax::kTrigger - 0x58], block[ax::kTrigger - 0x58 + 1]), 0);
  EXPECT_EQ(Int32(block[ax::kPosition - 0x58], block[ax::kPosition - 0x58 + 1]), 6000);
}

TEST_F(SimModel, IncrementalMovesAddToThePosition) {
  Ask(2, WritePdu(0x58, Block(2, -150, 100000)));
  std::this_thread::sleep_for(milliseconds(20));
  Ask(2, WritePdu(0x58, Block(2, -150, 100000)));
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(Feedback(2), -300);
}

TEST_F(SimModel, ATargetOutsideTheLimitsRaisesAnAlarmUntilReset) {
  // α limits ±90° at 10000/360 counts/°: 2500 counts. 3000 is beyond.
  Ask(1, WritePdu(0x58, Block(1, 3000, 1000)));
  std::uint32_t s = Status(1);
  EXPECT_NE(s & ax::kAlarm, 0u);
  EXPECT_EQ(s & ax::kMove, 0u);
  EXPECT_EQ(s & ax::kReady, 0u);
  auto alarm = Regs(Ask(1, ReadPdu(ax::kAlarmCode, 2)));
  EXPECT_EQ(Int32(alarm[0], alarm[1]), ax::kAlarmOvertravel);
  // No move starts while the alarm is set, even a valid one.
  Ask(1, WritePdu(0x58, Block(1, 100, 100000)));
  std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(Feedback(1), 0);
  // ALM-RST acts on the rising edge: set, then clear.
  Command(1, ax::kAlarmReset);
  Command(1, 0);
  s = Status(1);
  EXPECT_EQ(s & ax::kAlarm, 0u);
  EXPECT_EQ(Int32(Regs(Ask(1, ReadPdu(ax::kAlarmCode, 2)))[0],
                  Regs(Ask(1, ReadPdu(ax::kAlarmCode, 2)))[1]),
            0);
  Ask(1, WritePdu(0x58, Block(1, 100, 100000)));
  std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(Feedback(1), 100);
}

TEST_F(SimModel, StopFreezesTheAxisAndHomeReturnsToZero) {
  Ask(2, WritePdu(0x58, Block(1, 9000, 3000)));  // 90° at 30°/s: 150 real ms
  std::this_thread::sleep_for(milliseconds(30));
  Command(2, ax::kStop);
  Command(2, 0);
  const std::int32_t stopped = Feedback(2);
  EXPECT_GT(stopped, 0);
  EXPECT_LT(stopped, 9000);
  EXPECT_EQ(Status(2) & ax::kMove, 0u);
  std::this_thread::sleep_for(milliseconds(30));
  EXPECT_EQ(Feedback(2), stopped);

  Command(2, ax::kZhome);  // home speed 20°/s
  Command(2, 0);
  EXPECT_NE(Status(2) & ax::kMove, 0u);
  std::this_thread::sleep_for(milliseconds(200));
  EXPECT_EQ(Feedback(2), 0);
  EXPECT_EQ(Status(2) & ax::kMove, 0u);
}

TEST_F(SimModel, UndefinedRegistersAndBadValuesAreRefused) {
  EXPECT_EQ(Ask(1, ReadPdu(0x0000, 2)), (std::vector<std::uint8_t>{0x83, 0x02}));
  EXPECT_EQ(Ask(1, ReadPdu(0x007E, 10)), (std::vector<std::uint8_t>{0x83, 0x02}));  // runs past
  EXPECT_EQ(Ask(1, WritePdu(ax::kStatus, {0, 0})), (std::vector<std::uint8_t>{0x90, 0x02}));
  EXPECT_EQ(Ask(1, WritePdu(0x58, Block(7, 0, 1000))), (std::vector<std::uint8_t>{0x90, 0x03}));
  EXPECT_EQ(Ask(1, WritePdu(0x58, Block(1, 0, 0))), (std::vector<std::uint8_t>{0x90, 0x03}));
  EXPECT_EQ(Ask(1, {0x2B, 0x0E, 0x01, 0x00}), (std::vector<std::uint8_t>{0xAB, 0x01}));
  // The alternative feedback address mirrors the main one.
  EXPECT_EQ(Regs(Ask(1, ReadPdu(ax::kFeedbackAlt, 2))), Regs(Ask(1, ReadPdu(ax::kFeedback, 2))));
}

TEST_F(SimModel, EachUnitIdHasItsOwnRegisters) {
  Ask(3, WritePdu(0x58, Block(1, 500, 1000000)));
  std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(Feedback(3), 500);
  EXPECT_EQ(Feedback(1), 0);
  EXPECT_EQ(Feedback(2), 0);
  EXPECT_EQ(Feedback(4), 0);
}

TEST_F(SimModel, UnknownUnitsAreSilentOnRtuAndAGatewayErrorOnTcp) {
  EXPECT_EQ(sim_->HandleForTest(9, ReadPdu(ax::kStatus, 2), StageTransport::kRtu).kind,
            StageReply::Kind::kSilent);
  EXPECT_EQ(Ask(9, ReadPdu(ax::kStatus, 2)), (std::vector<std::uint8_t>{0x83, 0x0B}));
}

TEST_F(SimModel, TheDetectorArmCanBeLeftOut) {
  SimControl control;
  StageSimConfig c;
  c.serve_tcp = c.serve_rtu = false;
  c.axes[3].present = false;
  StageSimulator no_arm(c, control);
  EXPECT_EQ(no_arm.HandleForTest(4, ReadPdu(ax::kStatus, 2), StageTransport::kRtu).kind,
            StageReply::Kind::kSilent);
  EXPECT_EQ(no_arm.LivePose().delta, 0.0);
}

TEST_F(SimModel, TheControlUnitWritesSimControl) {
  Ask(cm::kDefaultUnitId, WritePdu(cm::kMountedTarget, {2}));
  EXPECT_EQ(control_.mounted(), MountedTarget::kDark);
  Ask(cm::kDefaultUnitId, WritePdu(cm::kSerialSilent, {1, 3, 4, 19, 2, 0x0001, 0x86A0}));
  const SerialFaults s = control_.serial();
  EXPECT_TRUE(s.silent);
  EXPECT_EQ(s.garbage_next, 3);
  EXPECT_EQ(s.truncate_next, 4);
  EXPECT_EQ(s.quality_code, 19);
  EXPECT_EQ(s.quality_count, 2);
  EXPECT_DOUBLE_EQ(s.vanish_seconds, 100.0);  // 0x000186A0 ms
  Ask(cm::kDefaultUnitId, WritePdu(cm::kModbusExceptionCode, {6, 2, 300, 1, 1, 1, 1}));
  const ModbusFaults m = control_.modbus();
  EXPECT_EQ(m.exception_code, 6);
  EXPECT_EQ(m.exception_count, 2);
  EXPECT_EQ(m.late_reply_ms, 300);
  EXPECT_EQ(m.late_count, 1);
  EXPECT_TRUE(m.drop_connection);
  EXPECT_TRUE(m.alarm_mid_move);
  EXPECT_TRUE(m.stall);
  // Reading back shows the same values, and the control unit itself is not subject to faults.
  const auto regs = Regs(Ask(cm::kDefaultUnitId, ReadPdu(0, cm::kRegisterCount)));
  EXPECT_EQ(regs[cm::kMountedTarget], 2);
  EXPECT_EQ(regs[cm::kModbusLateReplyMs], 300);
  EXPECT_EQ(control_.modbus().exception_count, 2);
}

TEST_F(SimModel, TheControlUnitRefusesBadValuesWithoutApplyingAnything) {
  EXPECT_EQ(Ask(cm::kDefaultUnitId, WritePdu(cm::kMountedTarget, {3})),
            (std::vector<std::uint8_t>{0x90, 0x03}));
  EXPECT_EQ(Ask(cm::kDefaultUnitId, WritePdu(cm::kModbusExceptionCode, {2, 5, 0, 0, 2})),
            (std::vector<std::uint8_t>{0x90, 0x03}));  // drop_connection = 2
  EXPECT_EQ(control_.modbus().exception_count, 0);
  EXPECT_EQ(Ask(cm::kDefaultUnitId, WritePdu(5, {1})), (std::vector<std::uint8_t>{0x90, 0x02}));
  // A read past the last register (33) is refused.
  EXPECT_EQ(Ask(cm::kDefaultUnitId, ReadPdu(cm::kRegisterCount - 4, 10)),
            (std::vector<std::uint8_t>{0x83, 0x02}));
  EXPECT_EQ(control_.mounted(), MountedTarget::kSample);
}

TEST_F(SimModel, ThePowerCycleRegisterCallsTheHook) {
  SimControl control;
  int cycles = 0;
  StageSimConfig c;
  c.serve_tcp = c.serve_rtu = false;
  StageSimulator sim(c, control, [&] { ++cycles; });
  sim.HandleForTest(cm::kDefaultUnitId, WritePdu(cm::kPowerCycleMeter, {1}), StageTransport::kTcp);
  EXPECT_EQ(cycles, 1);
  sim.HandleForTest(cm::kDefaultUnitId, WritePdu(cm::kPowerCycleMeter, {0}), StageTransport::kTcp);
  EXPECT_EQ(cycles, 1);
}

TEST_F(SimModel, ExceptionFaultsAnswerTheNextNAxisRequestsWithoutApplyingThem) {
  control_.set_modbus(ModbusFaults{.exception_code = 6, .exception_count = 2});
  EXPECT_EQ(Ask(1, WritePdu(0x58, Block(1, 100, 1000000))),
            (std::vector<std::uint8_t>{0x90, 0x06}));
  EXPECT_EQ(Ask(1, ReadPdu(ax::kFeedback, 2)), (std::vector<std::uint8_t>{0x83, 0x06}));
  EXPECT_EQ(control_.modbus().exception_count, 0);
  EXPECT_EQ(Feedback(1), 0);  // the refused write did not move the axis
}

TEST_F(SimModel, LateRepliesAndDropsFireOnce) {
  control_.set_modbus(ModbusFaults{.late_reply_ms = 250, .late_count = 1});
  EXPECT_EQ(sim_->HandleForTest(1, ReadPdu(ax::kStatus, 2), StageTransport::kTcp).delay,
            milliseconds(250));
  EXPECT_EQ(sim_->HandleForTest(1, ReadPdu(ax::kStatus, 2), StageTransport::kTcp).delay,
            milliseconds(0));
  control_.set_modbus(ModbusFaults{.drop_connection = true});
  EXPECT_EQ(sim_->HandleForTest(1, ReadPdu(ax::kStatus, 2), StageTransport::kTcp).kind,
            StageReply::Kind::kDrop);
  EXPECT_EQ(sim_->HandleForTest(1, ReadPdu(ax::kStatus, 2), StageTransport::kTcp).kind,
            StageReply::Kind::kReply);
}

TEST_F(SimModel, AnInjectedAlarmStopsTheNextMoveHalfWay) {
  control_.set_modbus(ModbusFaults{.alarm_mid_move = true});
  Ask(2, WritePdu(0x58, Block(1, 4000, 4000)));    // 40° at 40°/s: 1 s, alarm at 0.5 s
  EXPECT_FALSE(control_.modbus().alarm_mid_move);  // consumed by this move
  std::this_thread::sleep_for(milliseconds(80));
  const std::uint32_t s = Status(2);
  EXPECT_NE(s & ax::kAlarm, 0u);
  EXPECT_EQ(s & ax::kMove, 0u);
  const auto code = Regs(Ask(2, ReadPdu(ax::kAlarmCode, 2)));
  EXPECT_EQ(Int32(code[0], code[1]), ax::kAlarmMidMove);
  EXPECT_NEAR(Feedback(2), 2000, 2);
}

TEST_F(SimModel, AStalledMoveKeepsMoveSetUntilStopped) {
  control_.set_modbus(ModbusFaults{.stall = true});
  Ask(2, WritePdu(0x58, Block(1, 1000, 100000)));  // would take 10 ms sim
  std::this_thread::sleep_for(milliseconds(30));
  EXPECT_NE(Status(2) & ax::kMove, 0u);
  EXPECT_EQ(Feedback(2), 0);
  Command(2, ax::kStop);
  Command(2, 0);
  EXPECT_EQ(Status(2) & ax::kMove, 0u);
  // The next move is normal again.
  Ask(2, WritePdu(0x58, Block(1, 1000, 100000)));
  std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(Feedback(2), 1000);
}

}  // namespace
}  // namespace brdf::sim
