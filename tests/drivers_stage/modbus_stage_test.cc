// The Modbus stage driver against the stage simulator, over real Modbus TCP (127.0.0.1) and real
// Modbus RTU (a pty), on scaled time: moves, concurrency, limits, alarms, stalls, exceptions,
// late replies, dropped links and cancellation.
#include "drivers/stage/modbus_stage.h"

#include <gtest/gtest.h>
#include <modbus.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "tests/drivers_stage/stage_test_rig.h"
#include "tools/brdf-sim/stage/control_map.h"

namespace brdf::testing {
namespace {

using drivers::Axis;
using drivers::StageTarget;
using std::chrono::milliseconds;

constexpr double kTolerance = 0.05;

// StageTarget with designated initializers that leave the other axes empty.
struct To {
  std::optional<double> alpha = std::nullopt;
  std::optional<double> beta = std::nullopt;
  std::optional<double> gamma = std::nullopt;
  std::optional<double> delta = std::nullopt;
  operator StageTarget() const {  // NOLINT(google-explicit-constructor): reads as a target
    StageTarget t;
    t.alpha = alpha;
    t.beta = beta;
    t.gamma = gamma;
    t.delta = delta;
    return t;
  }
};

bool Contains(const Status& st, const std::string& text) {
  return st.message().find(text) != std::string::npos;
}

// Another Modbus master moves `unit` to `counts` almost at once (over TCP, while the stage under
// test may be on RTU: both reach the same simulated drives). True once the drive reports it.
::testing::AssertionResult JumpOverTcp(int port, int unit, std::int32_t counts) {
  modbus_t* tool = modbus_new_tcp("127.0.0.1", port);
  if (tool == nullptr || modbus_connect(tool) != 0) {
    if (tool != nullptr) modbus_free(tool);
    return ::testing::AssertionFailure() << "cannot connect: " << modbus_strerror(errno);
  }
  modbus_set_slave(tool, unit);
  auto put = [](std::uint16_t* at, std::int32_t v) {
    at[0] = static_cast<std::uint16_t>(static_cast<std::uint32_t>(v) >> 16);
    at[1] = static_cast<std::uint16_t>(static_cast<std::uint32_t>(v) & 0xFFFF);
  };
  std::uint16_t block[16] = {};
  put(&block[0x5A - 0x58], 1);           // absolute
  put(&block[0x5C - 0x58], counts);      // position
  put(&block[0x5E - 0x58], 10'000'000);  // counts/s: there at once
  put(&block[0x66 - 0x58], 1);           // trigger
  const int written = modbus_write_registers(tool, 0x58, 16, block);
  std::int32_t now = counts + 1;
  for (int i = 0; i < 100 && written == 16 && now != counts; ++i) {
    std::uint16_t regs[2] = {0, 0};
    if (modbus_read_registers(tool, 0xCC, 2, regs) == 2) {
      now = static_cast<std::int32_t>((static_cast<std::uint32_t>(regs[0]) << 16) | regs[1]);
    }
  }
  modbus_close(tool);
  modbus_free(tool);
  if (now != counts) return ::testing::AssertionFailure() << "the jump did not happen";
  return ::testing::AssertionSuccess();
}

class ModbusStageTest : public ::testing::TestWithParam<Link> {
 protected:
  void SetUp() override {
    ASSERT_TRUE(rig_.StartSim());
    ASSERT_TRUE(rig_.Connect(GetParam()));
  }
  // Moves and checks that it worked, for setting up a scene.
  void MoveOk(const StageTarget& t) {
    const Status st = rig_.stage().MoveTo(t, rig_.Ctx());
    ASSERT_TRUE(st.ok()) << st.ToString();
  }
  double SimDeg(int axis) { return rig_.sim().AxisSnapshot(axis).position_deg; }
  // Polls `done` every millisecond for up to 5 real seconds.
  template <typename Fn>
  static void WaitUntil(Fn done) {
    for (int i = 0; i < 5000 && !done(); ++i) std::this_thread::sleep_for(milliseconds(1));
  }

  StageRig rig_;
};

TEST_P(ModbusStageTest, MovesAllAxesConcurrentlyToTheirTargets) {
  const auto t0 = rig_.clock().Now();
  const Status st =
      rig_.stage().MoveTo(To{.alpha = 30, .beta = -60, .gamma = 45, .delta = 90}, rig_.Ctx());
  const double elapsed = rig_.SimSecondsSince(t0);
  ASSERT_TRUE(st.ok()) << st.ToString();

  // Where the driver says the axes are, and where the simulator has them.
  auto pose = rig_.stage().ReadPose(rig_.Ctx());
  ASSERT_TRUE(pose.ok()) << pose.status().ToString();
  EXPECT_NEAR(pose->alpha, 30, kTolerance);
  EXPECT_NEAR(pose->beta, -60, kTolerance);
  EXPECT_NEAR(pose->gamma, 45, kTolerance);
  EXPECT_NEAR(pose->delta, 90, kTolerance);
  const Pose live = rig_.sim().LivePose();
  EXPECT_NEAR(live.alpha, 30, kTolerance);
  EXPECT_NEAR(live.beta, -60, kTolerance);
  EXPECT_NEAR(live.gamma, 45, kTolerance);
  EXPECT_NEAR(live.delta, 90, kTolerance);

  // Concurrent: the longest axis (δ, 90° at 30°/s = 3 s) sets the pace, not the sum (7.5 s).
  EXPECT_GE(elapsed, 3.0 * 0.95);
  EXPECT_LT(elapsed, 7.5 * 0.8);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rig_.sim().AxisSnapshot(i).moves_started, 1) << i;
}

TEST_P(ModbusStageTest, MoveTimeFollowsDistanceOverSpeed) {
  auto t0 = rig_.clock().Now();
  MoveOk(To{.beta = 15});  // 15° at 30°/s: 0.5 s
  const double short_move = rig_.SimSecondsSince(t0);
  t0 = rig_.clock().Now();
  MoveOk(To{.beta = -75});  // 90°: 3 s
  const double long_move = rig_.SimSecondsSince(t0);
  EXPECT_GE(short_move, 0.5 * 0.95);
  EXPECT_GE(long_move, 3.0 * 0.95);
  EXPECT_GT(long_move - short_move, 1.0);  // 2.5 s apart, less polling and bus overhead
  EXPECT_LT(long_move, 3.0 + 2.5);         // done soon after arriving (polls every 0.1 s)
  EXPECT_NEAR(SimDeg(1), -75, kTolerance);
}

TEST_P(ModbusStageTest, RefusesTargetsOutsideTheLimitsBeforeAnythingMoves) {
  Status st = rig_.stage().MoveTo(To{.alpha = 95, .beta = 10}, rig_.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << st.ToString();
  EXPECT_TRUE(Contains(st, "alpha")) << st.message();
  EXPECT_TRUE(Contains(st, "max 90")) << st.message();
  st = rig_.stage().MoveTo(To{.beta = 10, .delta = -5}, rig_.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << st.ToString();
  EXPECT_TRUE(Contains(st, "delta")) << st.message();
  EXPECT_TRUE(Contains(st, "min 0")) << st.message();
  st = rig_.stage().MoveTo(To{.gamma = std::nan("")}, rig_.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << st.ToString();
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rig_.sim().AxisSnapshot(i).moves_started, 0) << i;
}

TEST_P(ModbusStageTest, AnAlarmMidMoveIsADeviceErrorUntilReset) {
  rig_.control().UpdateModbus([](sim::ModbusFaults& f) { f.alarm_mid_move = true; });
  Status st = rig_.stage().MoveTo(To{.beta = 60}, rig_.Ctx());
  ASSERT_EQ(st.code(), StatusCode::kDeviceError) << st.ToString();
  EXPECT_EQ(st.device_code(), sim::sim_axis::kAlarmMidMove);
  EXPECT_TRUE(Contains(st, "beta")) << st.message();
  EXPECT_TRUE(Contains(st, "ResetAlarm")) << st.message();
  EXPECT_NEAR(SimDeg(1), 30, 0.5);  // stopped half-way

  auto state = rig_.stage().ReadAxis(Axis::kBeta, rig_.Ctx());
  ASSERT_TRUE(state.ok()) << state.status().ToString();
  EXPECT_TRUE(state->alarm);
  EXPECT_EQ(state->alarm_code, sim::sim_axis::kAlarmMidMove);
  EXPECT_FALSE(state->ready);

  // No move starts while the alarm is set.
  st = rig_.stage().MoveTo(To{.alpha = 10, .beta = 0}, rig_.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kFailedPrecondition) << st.ToString();
  EXPECT_TRUE(Contains(st, "ResetAlarm(beta)")) << st.message();
  EXPECT_EQ(rig_.sim().AxisSnapshot(0).moves_started, 0);

  st = rig_.stage().ResetAlarm(Axis::kBeta, rig_.Ctx());
  ASSERT_TRUE(st.ok()) << st.ToString();
  MoveOk(To{.alpha = 10, .beta = 0});
  EXPECT_NEAR(SimDeg(0), 10, kTolerance);
  EXPECT_NEAR(SimDeg(1), 0, kTolerance);
}

TEST_P(ModbusStageTest, TheDrivesOwnOvertravelAlarmIsReported) {
  // The driver believes γ may go to 300°; the drive's limit is 180°.
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto config = rig.DriverConfig(GetParam());
  config.axes[2].max_deg = 300;
  ASSERT_TRUE(rig.Connect(config));
  const Status st = rig.stage().MoveTo(To{.gamma = 250}, rig.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kDeviceError) << st.ToString();
  EXPECT_EQ(st.device_code(), sim::sim_axis::kAlarmOvertravel);
  EXPECT_TRUE(Contains(st, "gamma")) << st.message();
  EXPECT_TRUE(rig.stage().ResetAlarm(Axis::kGamma, rig.Ctx()).ok());
}

TEST_P(ModbusStageTest, AStallTimesOutNamingTheAxisAndStopsIt) {
  rig_.control().UpdateModbus([](sim::ModbusFaults& f) { f.stall = true; });
  const auto t0 = rig_.clock().Now();
  const Status st = rig_.stage().MoveTo(To{.alpha = 5, .beta = 30}, rig_.Ctx());
  const double elapsed = rig_.SimSecondsSince(t0);
  ASSERT_EQ(st.code(), StatusCode::kTimeout) << st.ToString();
  // α started first and took the stall; β finished normally.
  EXPECT_TRUE(Contains(st, "axis alpha")) << st.message();
  EXPECT_GE(elapsed, 5.0 / 30 + 3.0 - 0.2);         // distance/speed + the 3 s margin
  EXPECT_FALSE(rig_.sim().AxisSnapshot(0).moving);  // the driver stopped it
  EXPECT_NEAR(SimDeg(1), 30, kTolerance);
}

TEST_P(ModbusStageTest, Exception02IsAConfigurationErrorWithoutRetry) {
  rig_.control().set_modbus({.exception_code = 2, .exception_count = 3});
  auto state = rig_.stage().ReadAxis(Axis::kAlpha, rig_.Ctx());
  ASSERT_EQ(state.status().code(), StatusCode::kConfigurationError) << state.status().ToString();
  EXPECT_TRUE(Contains(state.status(), "axis alpha")) << state.status().message();
  EXPECT_TRUE(Contains(state.status(), "register profile")) << state.status().message();
  EXPECT_EQ(rig_.control().modbus().exception_count, 2);  // exactly one request was made
}

TEST_P(ModbusStageTest, Exception06IsRetriedAndRecovers) {
  rig_.control().set_modbus({.exception_code = 6, .exception_count = 3});
  MoveOk(To{.gamma = -20});
  EXPECT_EQ(rig_.control().modbus().exception_count, 0);
  EXPECT_NEAR(SimDeg(2), -20, kTolerance);

  // A drive that stays busy is reported once the busy window (here 300 ms) has passed.
  rig_.control().set_modbus({.exception_code = 6, .exception_count = 1000});
  auto state = rig_.stage().ReadAxis(Axis::kGamma, rig_.Ctx());
  EXPECT_EQ(state.status().code(), StatusCode::kDeviceError) << state.status().ToString();
  EXPECT_EQ(state.status().device_code(), 6);
  EXPECT_TRUE(Contains(state.status(), "busy_window_ms")) << state.status().message();
  const int asked = 1000 - rig_.control().modbus().exception_count;
  // 5, 10, 20, 40, 80, 160 ms of back-off fill the window: about 7 answers, not hundreds.
  EXPECT_GE(asked, 4);
  EXPECT_LE(asked, 12);
}

// Exception 04 (an AZ: command execution disabled) is waited out like a busy drive: a burst
// shorter than the busy window costs nothing, a longer one is a kDeviceError 4 naming the window.
TEST_P(ModbusStageTest, Exception04BurstsAreRetriedWithinTheBusyWindow) {
  rig_.control().set_modbus({.exception_code = 4, .exception_count = 4});
  MoveOk(To{.alpha = 25});
  EXPECT_EQ(rig_.control().modbus().exception_count, 0);
  EXPECT_NEAR(SimDeg(0), 25, kTolerance);

  rig_.control().set_modbus({.exception_code = 4, .exception_count = 1000});
  const Status st = rig_.stage().MoveTo(To{.alpha = 30}, rig_.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kDeviceError) << st.ToString();
  EXPECT_EQ(st.device_code(), 4);
  EXPECT_TRUE(Contains(st, "exception 4")) << st.message();
  EXPECT_TRUE(Contains(st, "busy_window_ms")) << st.message();
  rig_.control().set_modbus({});
  EXPECT_NEAR(SimDeg(0), 25, kTolerance);  // the refused block moved nothing
}

// A drive set to lower word first: every 32-bit value the driver writes arrives with its halves
// swapped, the drive refuses the block, and the error names the profile's word_order.
TEST_P(ModbusStageTest, AWordOrderMismatchIsNamedInTheError) {
  StageRig rig;
  auto sim_config = DefaultSimConfig();
  for (auto& axis : sim_config.axes) axis.word_order = sim::SimWordOrder::kLowFirst;
  ASSERT_TRUE(rig.StartSim(std::move(sim_config)));
  ASSERT_TRUE(rig.Connect(GetParam()));  // status reads answer, whatever the word order
  const Status st = rig.stage().MoveTo(To{.alpha = 10}, rig.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kConfigurationError) << st.ToString();
  EXPECT_TRUE(Contains(st, "word_order (\"high_first\")")) << st.message();
  EXPECT_TRUE(Contains(st, "profile 'az'")) << st.message();
  EXPECT_TRUE(Contains(st, "operation block")) << st.message();
}

TEST_P(ModbusStageTest, ALateReplyIsNeverTakenForTheNextAnswer) {
  MoveOk(To{.alpha = 10, .beta = -20});
  // The reply arrives after the 200 ms response timeout (and within the RTU drain window).
  rig_.control().set_modbus({.late_reply_ms = 300, .late_count = 1});
  auto alpha = rig_.stage().ReadAxis(Axis::kAlpha, rig_.Ctx());
  ASSERT_TRUE(alpha.ok()) << alpha.status().ToString();
  EXPECT_NEAR(alpha->position_deg, 10, kTolerance);
  auto beta = rig_.stage().ReadAxis(Axis::kBeta, rig_.Ctx());
  ASSERT_TRUE(beta.ok()) << beta.status().ToString();
  EXPECT_NEAR(beta->position_deg, -20, kTolerance);

  // Without retries the late request times out. Then another master (over TCP) moves α, so a
  // stale reply (α = 10°) taken for the next answer would show.
  // (The first stage lets go of the line: an RTU line has one master.)
  rig_.stage().Disconnect();
  auto config = rig_.DriverConfig(GetParam());
  config.buses[0].timeout_retries = 0;
  auto stage = drivers::stage::ModbusStage::Create(config);
  ASSERT_TRUE(stage.ok());
  ASSERT_TRUE((*stage)->Connect(rig_.Ctx()).ok());
  rig_.control().set_modbus({.late_reply_ms = 300, .late_count = 1});
  auto late = (*stage)->ReadPose(rig_.Ctx());
  EXPECT_EQ(late.status().code(), StatusCode::kTimeout) << late.status().ToString();
  EXPECT_TRUE(Contains(late.status(), "axis alpha")) << late.status().message();
  ASSERT_TRUE(JumpOverTcp(rig_.sim().tcp_port(), 1, 40 * 10000 / 360));
  for (int i = 0; i < 3; ++i) {
    auto pose = (*stage)->ReadPose(rig_.Ctx());
    ASSERT_TRUE(pose.ok()) << pose.status().ToString();
    EXPECT_NEAR(pose->alpha, 40, kTolerance);
    EXPECT_NEAR(pose->beta, -20, kTolerance);
    EXPECT_NEAR(pose->gamma, 0, kTolerance);
  }
}

TEST_P(ModbusStageTest, CancellationStopsTheAxesAndReturnsCancelled) {
  CancelToken cancel;
  std::thread canceller([&] {
    // Once both axes of the 2.7 s move have covered a few degrees.
    WaitUntil([&] { return std::abs(SimDeg(0)) > 3 && std::abs(SimDeg(2)) > 3; });
    cancel.Cancel("operator pressed abort");
  });
  const Status st = rig_.stage().MoveTo(To{.alpha = 80, .gamma = -80}, rig_.Ctx(120, cancel));
  canceller.join();
  ASSERT_EQ(st.code(), StatusCode::kCancelled) << st.ToString();
  EXPECT_TRUE(Contains(st, "operator pressed abort")) << st.message();
  EXPECT_TRUE(Contains(st, "stopped")) << st.message();
  for (int axis : {0, 2}) {
    const sim::SimAxisSnapshot s = rig_.sim().AxisSnapshot(axis);
    EXPECT_FALSE(s.moving) << axis;
    EXPECT_GT(std::abs(s.position_deg), 3) << axis;
    EXPECT_LT(std::abs(s.position_deg), 79) << axis;
  }
  // Stopped means stopped: nothing moves on afterwards.
  const double alpha = SimDeg(0);
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_DOUBLE_EQ(SimDeg(0), alpha);
}

TEST_P(ModbusStageTest, StopHaltsAMoveInProgress) {
  Status move_status;
  std::thread mover([&] { move_status = rig_.stage().MoveTo(To{.beta = 90}, rig_.Ctx()); });
  WaitUntil([&] { return SimDeg(1) > 3; });
  const Status st = rig_.stage().Stop(rig_.Ctx());
  mover.join();
  ASSERT_TRUE(st.ok()) << st.ToString();
  EXPECT_EQ(move_status.code(), StatusCode::kDeviceError) << move_status.ToString();
  EXPECT_TRUE(Contains(move_status, "short of its target")) << move_status.message();
  EXPECT_FALSE(rig_.sim().AxisSnapshot(1).moving);
  EXPECT_LT(SimDeg(1), 89);
}

TEST_P(ModbusStageTest, HomeReturnsTheAxisToZero) {
  MoveOk(To{.gamma = 40});
  const Status st = rig_.stage().Home(Axis::kGamma, rig_.Ctx());
  ASSERT_TRUE(st.ok()) << st.ToString();
  EXPECT_NEAR(SimDeg(2), 0, kTolerance);
  auto state = rig_.stage().ReadAxis(Axis::kGamma, rig_.Ctx());
  ASSERT_TRUE(state.ok());
  EXPECT_NEAR(state->position_deg, 0, kTolerance);
  EXPECT_TRUE(state->in_position);
  EXPECT_TRUE(state->ready);
  EXPECT_FALSE(state->moving);
}

TEST_P(ModbusStageTest, AWrongRegisterAddressIsAConfigurationError) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto config = rig.DriverConfig(GetParam());
  config.profile.feedback_position.address = 0x0200;  // not a register of this drive
  ASSERT_TRUE(rig.Connect(config));                   // status reads still work
  auto pose = rig.stage().ReadPose(rig.Ctx());
  EXPECT_EQ(pose.status().code(), StatusCode::kConfigurationError) << pose.status().ToString();
  EXPECT_TRUE(Contains(pose.status(), "0x0200")) << pose.status().message();
}

TEST_P(ModbusStageTest, AnAxisTheRigDoesNotHaveIsRefused) {
  StageRig rig;
  auto sim_config = DefaultSimConfig();
  sim_config.axes[3].present = false;  // no motorized detector arm
  ASSERT_TRUE(rig.StartSim(sim_config));
  ASSERT_TRUE(rig.Connect(GetParam()));
  EXPECT_FALSE(rig.stage().HasAxis(Axis::kDelta));
  const Status st = rig.stage().MoveTo(To{.alpha = 1, .delta = 10}, rig.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << st.ToString();
  auto pose = rig.stage().ReadPose(rig.Ctx());
  ASSERT_TRUE(pose.ok());
  EXPECT_EQ(pose->delta, 0);
}

TEST_P(ModbusStageTest, AMissingUnitFailsAtConnect) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto config = rig.DriverConfig(GetParam());
  config.axes[2].unit_id = 9;  // nobody answers to 9
  config.buses[0].timeout_retries = 0;
  auto stage = drivers::stage::ModbusStage::Create(config);
  ASSERT_TRUE(stage.ok());
  const Status st = (*stage)->Connect(rig.Ctx());
  EXPECT_FALSE(st.ok());
  EXPECT_FALSE((*stage)->connected());
  EXPECT_TRUE(Contains(st, "axis gamma (unit 9")) << st.message();
  // Over TCP the gateway says so (exception 0B); on an RTU line nobody answers.
  EXPECT_EQ(st.code(), GetParam() == Link::kTcp ? StatusCode::kDeviceError : StatusCode::kTimeout)
      << st.ToString();
}

TEST_P(ModbusStageTest, CallsBeforeConnectAreRefused) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto stage = drivers::stage::ModbusStage::Create(rig.DriverConfig(GetParam()));
  ASSERT_TRUE(stage.ok());
  EXPECT_EQ((*stage)->MoveTo(To{.alpha = 1}, rig.Ctx()).code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ((*stage)->ReadPose(rig.Ctx()).status().code(), StatusCode::kFailedPrecondition);
}

INSTANTIATE_TEST_SUITE_P(Links, ModbusStageTest, ::testing::Values(Link::kTcp, Link::kRtu),
                         [](const auto& param_info) {
                           return param_info.param == Link::kTcp ? std::string("Tcp") : "Rtu";
                         });

// ---- TCP only -------------------------------------------------------------------------------

TEST(ModbusStageTcp, ADroppedConnectionIsReestablished) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  ASSERT_TRUE(rig.Connect(Link::kTcp));
  rig.control().set_modbus({.drop_connection = true});
  Status st = rig.stage().MoveTo(To{.alpha = 20, .beta = 20}, rig.Ctx());
  ASSERT_TRUE(st.ok()) << st.ToString();
  EXPECT_FALSE(rig.control().modbus().drop_connection);  // it did fire
  EXPECT_NEAR(rig.sim().LivePose().alpha, 20, kTolerance);

  // And again in the middle of the polling.
  std::thread dropper([&] {
    std::this_thread::sleep_for(milliseconds(20));
    rig.control().UpdateModbus([](sim::ModbusFaults& f) { f.drop_connection = true; });
  });
  st = rig.stage().MoveTo(To{.alpha = -20, .beta = -20}, rig.Ctx());
  dropper.join();
  ASSERT_TRUE(st.ok()) << st.ToString();
  EXPECT_NEAR(rig.sim().LivePose().beta, -20, kTolerance);
}

TEST(ModbusStageTcp, AVanishedDriveIsDisconnectedAndRecoversWhenBack) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto config = rig.DriverConfig(Link::kTcp);
  config.buses[0].reconnect_attempts = 2;
  ASSERT_TRUE(rig.Connect(config));
  const int port = rig.sim().tcp_port();
  rig.sim().Shutdown();

  auto gone = rig.stage().ReadAxis(Axis::kAlpha, rig.Ctx());
  EXPECT_EQ(gone.status().code(), StatusCode::kDisconnected) << gone.status().ToString();
  EXPECT_TRUE(Contains(gone.status(), "127.0.0.1:" + std::to_string(port)))
      << gone.status().message();

  auto back = DefaultSimConfig();
  back.tcp_port = port;
  ASSERT_TRUE(rig.StartSim(back));
  auto state = rig.stage().ReadAxis(Axis::kAlpha, rig.Ctx());
  ASSERT_TRUE(state.ok()) << state.status().ToString();
  EXPECT_TRUE(rig.stage().MoveTo(To{.alpha = 3}, rig.Ctx()).ok());
}

TEST(ModbusStageTcp, NothingListeningIsDisconnectedAtConnect) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto config = rig.DriverConfig(Link::kTcp);
  config.buses[0].reconnect_attempts = 2;
  rig.sim().Shutdown();
  auto stage = drivers::stage::ModbusStage::Create(config);
  ASSERT_TRUE(stage.ok());
  const Status st = (*stage)->Connect(rig.Ctx());
  EXPECT_EQ(st.code(), StatusCode::kDisconnected) << st.ToString();
  EXPECT_TRUE(Contains(st, "attempt 2 of 2")) << st.message();
}

TEST(ModbusStageTcp, SeveralClientsAndTheControlUnitShareTheEndpoint) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  ASSERT_TRUE(rig.Connect(Link::kTcp));
  // A second client (an operator's tool) sets a fault through the control unit over Modbus.
  modbus_t* tool = modbus_new_tcp("127.0.0.1", rig.sim().tcp_port());
  ASSERT_NE(tool, nullptr);
  ASSERT_EQ(modbus_connect(tool), 0) << modbus_strerror(errno);
  modbus_set_slave(tool, sim::control_map::kDefaultUnitId);
  const std::uint16_t busy[] = {6, 2};
  EXPECT_EQ(modbus_write_registers(tool, sim::control_map::kModbusExceptionCode, 2, busy), 2);
  EXPECT_EQ(rig.control().modbus().exception_count, 2);
  // The stage, on its own connection, rides over the busy replies.
  const Status st = rig.stage().MoveTo(To{.alpha = 7}, rig.Ctx());
  EXPECT_TRUE(st.ok()) << st.ToString();
  std::uint16_t regs[2] = {0, 0};
  EXPECT_EQ(modbus_read_registers(tool, sim::control_map::kModbusExceptionCode, 2, regs), 2);
  EXPECT_EQ(regs[1], 0);  // both consumed
  // The tool reads α's feedback on unit 1 over the same endpoint.
  modbus_set_slave(tool, 1);
  EXPECT_EQ(modbus_read_registers(tool, sim::sim_axis::kFeedback, 2, regs), 2);
  const auto counts =
      static_cast<std::int32_t>((static_cast<std::uint32_t>(regs[0]) << 16) | regs[1]);
  EXPECT_EQ(counts, std::lround(7 * 10000.0 / 360.0));
  modbus_close(tool);
  modbus_free(tool);
}

// ---- Two buses ------------------------------------------------------------------------------

TEST(ModbusStageBuses, AxesOnTcpAndRtuMoveTogether) {
  StageRig rig;
  ASSERT_TRUE(rig.StartSim());
  auto config = rig.DriverConfig(Link::kTcp);
  config.buses.push_back(rig.Bus(Link::kRtu));
  config.axes[2].bus = 1;  // γ and δ on the RS-485 line
  config.axes[3].bus = 1;
  ASSERT_TRUE(rig.Connect(config));
  const auto t0 = rig.clock().Now();
  const Status st =
      rig.stage().MoveTo(To{.alpha = -45, .beta = 60, .gamma = 60, .delta = 60}, rig.Ctx());
  const double elapsed = rig.SimSecondsSince(t0);
  ASSERT_TRUE(st.ok()) << st.ToString();
  const Pose live = rig.sim().LivePose();
  EXPECT_NEAR(live.alpha, -45, kTolerance);
  EXPECT_NEAR(live.beta, 60, kTolerance);
  EXPECT_NEAR(live.gamma, 60, kTolerance);
  EXPECT_NEAR(live.delta, 60, kTolerance);
  EXPECT_LT(elapsed, 2.0 * 4 * 0.8);  // concurrent, not 4 × 2 s
}

}  // namespace
}  // namespace brdf::testing
