// The pure pieces of the stage driver: 32-bit packing in both word orders, degrees ↔ counts,
// status decoding, register profiles and their validation.
#include "drivers/stage/modbus_codec.h"

#include <gtest/gtest.h>
#include <modbus.h>

#include <cerrno>
#include <cmath>
#include <limits>
#include <random>

#include "drivers/stage/modbus_errors.h"
#include "drivers/stage/modbus_stage.h"
#include "drivers/stage/register_profile.h"

namespace brdf::drivers::stage {
namespace {

TEST(PackInt32, HighWordFirstPutsUpperHalfAtLowerAddress) {
  const auto regs = PackInt32(0x12345678, WordOrder::kHighFirst);
  EXPECT_EQ(regs[0], 0x1234);
  EXPECT_EQ(regs[1], 0x5678);
}

TEST(PackInt32, LowWordFirstSwapsTheHalves) {
  const auto regs = PackInt32(0x12345678, WordOrder::kLowFirst);
  EXPECT_EQ(regs[0], 0x5678);
  EXPECT_EQ(regs[1], 0x1234);
}

TEST(PackInt32, NegativeValuesAreTwosComplement) {
  const auto minus_one = PackInt32(-1, WordOrder::kHighFirst);
  EXPECT_EQ(minus_one[0], 0xFFFF);
  EXPECT_EQ(minus_one[1], 0xFFFF);
  const auto minus_big = PackInt32(-100000, WordOrder::kHighFirst);  // 0xFFFE7960
  EXPECT_EQ(minus_big[0], 0xFFFE);
  EXPECT_EQ(minus_big[1], 0x7960);
}

TEST(UnpackInt32, HighWordAtOrAbove0x8000IsNegative) {
  // The case MODBUS_GET_INT32_FROM_INT16 gets wrong without a cast.
  EXPECT_EQ(UnpackInt32(0x8000, 0x0000, WordOrder::kHighFirst),
            std::numeric_limits<std::int32_t>::min());
  EXPECT_EQ(UnpackInt32(0xFFFE, 0x7960, WordOrder::kHighFirst), -100000);
  EXPECT_EQ(UnpackInt32(0x7960, 0xFFFE, WordOrder::kLowFirst), -100000);
  EXPECT_EQ(UnpackInt32(0x7FFF, 0xFFFF, WordOrder::kHighFirst),
            std::numeric_limits<std::int32_t>::max());
}

TEST(PackUnpack, RoundTripsRandomValuesInBothOrders) {
  std::mt19937 rng(650);
  std::uniform_int_distribution<std::int32_t> any(std::numeric_limits<std::int32_t>::min(),
                                                  std::numeric_limits<std::int32_t>::max());
  for (int i = 0; i < 20000; ++i) {
    const std::int32_t v = any(rng);
    for (WordOrder order : {WordOrder::kHighFirst, WordOrder::kLowFirst}) {
      const auto r = PackInt32(v, order);
      ASSERT_EQ(UnpackInt32(r[0], r[1], order), v) << v;
    }
  }
}

TEST(DecodeSigned, OneWordFieldsAreSignExtended) {
  const std::uint16_t reg[] = {0xFFF6};
  EXPECT_EQ(DecodeSigned(reg, WordOrder::kHighFirst), -10);
  EXPECT_EQ(DecodeUnsigned(reg, WordOrder::kHighFirst), 0xFFF6u);
}

TEST(EncodeField, WritesOneOrTwoWords) {
  std::uint16_t one[1] = {0};
  EncodeField(-2, 1, WordOrder::kHighFirst, one);
  EXPECT_EQ(one[0], 0xFFFE);
  std::uint16_t two[2] = {0, 0};
  EncodeField(70000, 2, WordOrder::kLowFirst, two);
  EXPECT_EQ(two[0], 70000 & 0xFFFF);
  EXPECT_EQ(two[1], 1);
}

TEST(FitsField, ChecksSignedAndUnsignedRanges) {
  EXPECT_TRUE(FitsField(32767, 1, true));
  EXPECT_FALSE(FitsField(32768, 1, true));
  EXPECT_TRUE(FitsField(65535, 1, false));
  EXPECT_FALSE(FitsField(-1, 1, false));
  EXPECT_TRUE(FitsField(std::numeric_limits<std::int32_t>::min(), 2, true));
  EXPECT_FALSE(FitsField(std::int64_t{1} << 31, 2, true));
  EXPECT_FALSE(FitsField(0, 3, true));
}

TEST(DegreesToCounts, RoundsHalfAwayFromZeroAndAddsTheOffset) {
  const double cpd = 10000.0 / 360.0;  // 27.777…
  EXPECT_EQ(*DegreesToCounts(90, cpd, 0), 2500);
  EXPECT_EQ(*DegreesToCounts(-90, cpd, 0), -2500);
  EXPECT_EQ(*DegreesToCounts(1, cpd, 0), 28);    // 27.78 → 28
  EXPECT_EQ(*DegreesToCounts(-1, cpd, 0), -28);  // symmetric
  EXPECT_EQ(*DegreesToCounts(0.5, 1.0, 0), 1);   // half away from zero
  EXPECT_EQ(*DegreesToCounts(-0.5, 1.0, 0), -1);
  EXPECT_EQ(*DegreesToCounts(10, 100, 5000), 6000);
  EXPECT_DOUBLE_EQ(CountsToDegrees(6000, 100, 5000), 10.0);
}

TEST(DegreesToCounts, RejectsNonFiniteAndOverflowingAngles) {
  EXPECT_EQ(DegreesToCounts(std::nan(""), 100, 0).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(DegreesToCounts(INFINITY, 100, 0).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(DegreesToCounts(3e7, 100, 0).status().code(), StatusCode::kInvalidArgument);
}

TEST(DegreesToCounts, RoundTripErrorIsAtMostHalfACount) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> deg(-720, 720);
  std::uniform_real_distribution<double> cpd(0.5, 2000);
  for (int i = 0; i < 20000; ++i) {
    const double d = deg(rng);
    const double c = cpd(rng);
    auto counts = DegreesToCounts(d, c, 123);
    ASSERT_TRUE(counts.ok());
    ASSERT_LE(std::abs(CountsToDegrees(*counts, c, 123) - d), 0.5 / c + 1e-9) << d << " " << c;
  }
}

TEST(DecodeStatus, AppliesTheAzMasks) {
  const StatusBits bits = RegisterProfile::AzDefault().status_bits;
  const StatusFlags moving = DecodeStatus(1u << 13, bits);
  EXPECT_TRUE(moving.moving);
  EXPECT_FALSE(moving.in_position);
  EXPECT_FALSE(MoveComplete(moving));
  const StatusFlags done = DecodeStatus((1u << 5) | (1u << 14), bits);
  EXPECT_TRUE(done.ready);
  EXPECT_TRUE(MoveComplete(done));
  const StatusFlags alarm = DecodeStatus((1u << 7) | (1u << 14), bits);
  EXPECT_TRUE(alarm.alarm);
  EXPECT_FALSE(MoveComplete(alarm));
  EXPECT_TRUE(DecodeStatus(1u << 8, bits).busy);
}

TEST(DecodeStatus, WithoutAnInPositionBitItFollowsMoveAndAlarm) {
  StatusBits bits{.ready = 1, .alarm = 2, .busy = 0, .moving = 4, .in_position = 0};
  EXPECT_TRUE(DecodeStatus(0, bits).in_position);
  EXPECT_FALSE(DecodeStatus(4, bits).in_position);
  EXPECT_FALSE(DecodeStatus(2, bits).in_position);
}

TEST(RegisterProfile, AzDefaultMatchesTheReferenceMap) {
  const RegisterProfile p = RegisterProfile::AzDefault();
  EXPECT_TRUE(ValidateProfile(p).ok());
  EXPECT_EQ(p.position.address, 0x005C);
  EXPECT_EQ(p.speed.address, 0x005E);
  EXPECT_EQ(p.trigger.address, 0x0066);
  EXPECT_EQ(p.operation_type.address, 0x005A);
  EXPECT_EQ(p.status.address, 0x007E);
  EXPECT_EQ(p.alarm_code.address, 0x0080);
  EXPECT_EQ(p.feedback_position.address, 0x00CC);
  EXPECT_EQ(p.input_command.address, 0x007C);
  EXPECT_EQ(p.alarm_reset.value, 1u << 7);
  EXPECT_EQ(p.home.value, 1u << 4);
  EXPECT_EQ(p.stop.value, 1u << 5);
  // One FC16 from the data number through the trigger.
  const BlockSpan span = OperationBlockSpan(p);
  EXPECT_EQ(span.start, 0x0058);
  EXPECT_EQ(span.count, 0x0068 - 0x0058);
}

TEST(RegisterProfile, LeadshineAndMoonsAreExpressibleButUnverified) {
  for (const RegisterProfile& p : {RegisterProfile::Leadshine(), RegisterProfile::Moons()}) {
    EXPECT_TRUE(ValidateProfile(p).ok()) << p.name << ": " << ValidateProfile(p).ToString();
    EXPECT_FALSE(p.verified_against_hardware) << p.name;
    EXPECT_NE(p.trigger_style, TriggerStyle::kTriggerInBlock) << p.name;
    // The trigger is a separate write: the block FC16 stops before it.
    const BlockSpan span = OperationBlockSpan(p);
    EXPECT_FALSE(p.trigger.address >= span.start && p.trigger.address < span.start + span.count);
  }
  EXPECT_EQ(RegisterProfile::Leadshine().trigger.address, 0x6002);
  EXPECT_EQ(RegisterProfile::Leadshine().trigger_value, 0x0010);
  EXPECT_EQ(RegisterProfile::Leadshine().status.address, 0x1003);
  EXPECT_EQ(RegisterProfile::Moons().trigger.address, 124);
  EXPECT_EQ(RegisterProfile::Moons().position.address, 30);
  EXPECT_EQ(RegisterProfile::Moons().status.address, 1);
}

void ExpectConfigError(const Status& st, const std::string& field) {
  EXPECT_EQ(st.code(), StatusCode::kConfigurationError) << st.ToString();
  EXPECT_NE(st.message().find(field), std::string::npos) << st.message();
}

TEST(ValidateProfile, NamesTheBadField) {
  RegisterProfile p = RegisterProfile::AzDefault();
  p.status.words = 3;
  ExpectConfigError(ValidateProfile(p), "status.words");

  p = RegisterProfile::AzDefault();
  p.position.address = 0x0064;  // on top of the current constant
  ExpectConfigError(ValidateProfile(p), "overlaps");

  p = RegisterProfile::AzDefault();
  p.trigger.address = 0x0200;  // the block would span more than one FC16
  ExpectConfigError(ValidateProfile(p), "block_start");

  p = RegisterProfile::AzDefault();
  p.status_bits.moving = 0;
  ExpectConfigError(ValidateProfile(p), "status_bits.moving");

  p = RegisterProfile::AzDefault();
  p.input_command = {};
  ExpectConfigError(ValidateProfile(p), "home");

  p = RegisterProfile::AzDefault();
  p.stop = {};
  ExpectConfigError(ValidateProfile(p), "stop");

  p = RegisterProfile::Leadshine();
  p.status_bits.in_position = 0x10000;  // 16-bit status word
  ExpectConfigError(ValidateProfile(p), "status_bits.in_position");

  p = RegisterProfile::AzDefault();
  p.speed_scale = 0;
  ExpectConfigError(ValidateProfile(p), "speed_scale");
}

TEST(ValidateAxis, NamesTheAxisAndField) {
  const RegisterProfile az = RegisterProfile::AzDefault();
  AxisConfig a;
  a.present = true;
  a.unit_id = 1;
  EXPECT_TRUE(ValidateAxis(Axis::kBeta, a, az).ok());

  AxisConfig bad = a;
  bad.unit_id = 0;
  ExpectConfigError(ValidateAxis(Axis::kBeta, bad, az), "beta");
  ExpectConfigError(ValidateAxis(Axis::kBeta, bad, az), "unit_id");

  bad = a;
  bad.min_deg = 10;
  bad.max_deg = -10;
  ExpectConfigError(ValidateAxis(Axis::kGamma, bad, az), "min_deg/max_deg");

  bad = a;
  bad.speed_deg_s = -1;
  ExpectConfigError(ValidateAxis(Axis::kAlpha, bad, az), "speed_deg_s");

  // Leadshine's speed is a 16-bit rpm register: an absurd speed does not fit.
  bad = a;
  bad.speed_deg_s = 1e9;
  ExpectConfigError(ValidateAxis(Axis::kAlpha, bad, RegisterProfile::Leadshine()), "speed_deg_s");

  bad = a;
  bad.counts_per_degree = 1e8;  // ±180° no longer fits 32 bits
  ExpectConfigError(ValidateAxis(Axis::kDelta, bad, az), "min_deg");

  AxisConfig absent;  // absent axes are not checked
  EXPECT_TRUE(ValidateAxis(Axis::kDelta, absent, az).ok());
}

TEST(ValidateStageConfig, RequiresAlphaBetaAndDistinctUnits) {
  ModbusStageConfig c;
  c.buses = {BusConfig{}};
  c.axes[0] = AxisConfig{.present = true, .bus = 0, .unit_id = 1};
  c.axes[1] = AxisConfig{.present = true, .bus = 0, .unit_id = 2};
  EXPECT_TRUE(ValidateStageConfig(c).ok()) << ValidateStageConfig(c).ToString();

  ModbusStageConfig bad = c;
  bad.axes[1].present = false;
  ExpectConfigError(ValidateStageConfig(bad), "axes.beta.present");

  bad = c;
  bad.axes[1].unit_id = 1;
  ExpectConfigError(ValidateStageConfig(bad), "unit_id");

  bad = c;
  bad.axes[1].bus = 1;
  ExpectConfigError(ValidateStageConfig(bad), "axes.beta.bus");

  bad = c;
  bad.buses.clear();
  ExpectConfigError(ValidateStageConfig(bad), "buses");

  bad = c;
  bad.position_tolerance_deg = 0.001;  // less than a count at 27.8 counts/°
  ExpectConfigError(ValidateStageConfig(bad), "position_tolerance_deg");

  bad = c;
  bad.buses[0].endpoint = RtuEndpoint{"/dev/ttyUSB0", 115200, 'X', 8, 1};
  ExpectConfigError(ValidateStageConfig(bad), "parity");

  bad = c;
  bad.buses[0].endpoint = TcpEndpoint{"10.0.0.2", 0};
  ExpectConfigError(ValidateStageConfig(bad), "port");
}

TEST(ModbusErrors, ClassifiesExceptionsAndLinkErrors) {
  EXPECT_EQ(ClassifyModbusErrno(EMBXILADD), ModbusFailure::kIllegalRequest);
  EXPECT_EQ(ClassifyModbusErrno(EMBXILVAL), ModbusFailure::kIllegalRequest);
  EXPECT_EQ(ClassifyModbusErrno(EMBXSBUSY), ModbusFailure::kBusy);
  EXPECT_EQ(ClassifyModbusErrno(EMBXSFAIL), ModbusFailure::kBusy);  // AZ: execution disabled
  EXPECT_EQ(ClassifyModbusErrno(EMBXGTAR), ModbusFailure::kDeviceException);
  EXPECT_EQ(ClassifyModbusErrno(ETIMEDOUT), ModbusFailure::kTimeout);
  EXPECT_EQ(ClassifyModbusErrno(EMBBADDATA), ModbusFailure::kStaleOrGarbled);
  EXPECT_EQ(ClassifyModbusErrno(EMBBADCRC), ModbusFailure::kStaleOrGarbled);
  EXPECT_EQ(ClassifyModbusErrno(ECONNRESET), ModbusFailure::kLinkDown);
  EXPECT_EQ(ClassifyModbusErrno(EPIPE), ModbusFailure::kLinkDown);
  EXPECT_EQ(ModbusExceptionCode(EMBXSBUSY), 6);
  EXPECT_EQ(ModbusExceptionCode(ETIMEDOUT), 0);
}

}  // namespace
}  // namespace brdf::drivers::stage
