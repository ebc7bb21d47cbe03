// The simulated drives' settings, as on an AZ drive: word order (upper word first by default,
// lower word first as an option) and the unit the ramp rates are read in.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "tools/brdf-sim/stage/simulator.h"

namespace brdf::sim {
namespace {

using Bytes = std::vector<std::uint8_t>;
using SteadyClock = std::chrono::steady_clock;

const Bytes kReadStatus{0x03, 0x00, 0x7E, 0x00, 0x02};

StageSimConfig NoEndpoints() {
  StageSimConfig c;
  c.serve_tcp = false;
  c.serve_rtu = false;
  return c;
}

// FC16 of the block 0x0058–0x0067, upper word first: type 1 (absolute), position, speed, the
// two rates, current 1000, trigger 1. brdfd writes both rates as 1,000,000.
Bytes UpperFirstBlock(std::int32_t position, std::int32_t speed, std::int32_t rate) {
  Bytes pdu{0x10, 0x00, 0x58, 0x00, 0x10, 0x20};
  for (std::int32_t v : {0, 1, position, speed, rate, rate, 1000, 1}) {
    const auto u = static_cast<std::uint32_t>(v);
    for (int shift : {24, 16, 8, 0}) pdu.push_back(static_cast<std::uint8_t>(u >> shift));
  }
  return pdu;
}

// The AZ status word at rest is READY | IN-POS = 0x00004020.
TEST(StageWordOrder, UpperWordFirstIsTheDefaultAndLowerWordFirstSwapsTheRegisters) {
  SimControl control;
  StageSimConfig upper;
  upper.serve_tcp = false;
  upper.serve_rtu = false;
  StageSimulator a(upper, control);
  EXPECT_EQ(a.HandleForTest(1, kReadStatus, StageTransport::kTcp).pdu,
            (Bytes{0x03, 4, 0x00, 0x00, 0x40, 0x20}));

  StageSimConfig lower = upper;
  for (auto& axis : lower.axes) axis.word_order = SimWordOrder::kLowFirst;
  StageSimulator b(lower, control);
  EXPECT_EQ(b.HandleForTest(1, kReadStatus, StageTransport::kTcp).pdu,
            (Bytes{0x03, 4, 0x40, 0x20, 0x00, 0x00}));

  // A block written lower word first moves the lower-word-first drive to its target: position
  // 1000 = 0x000003E8, speed 100000 = 0x000186A0, type 1, trigger 1.
  const Bytes block{0x10, 0x00, 0x58, 0x00, 0x10, 0x20, 0x00, 0x00, 0x00, 0x00,  // data number 0
                    0x00, 0x01, 0x00, 0x00,                                      // type 1
                    0x03, 0xE8, 0x00, 0x00,                                      // position 1000
                    0x86, 0xA0, 0x00, 0x01,                                      // speed 100000
                    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,              // rates
                    0x00, 0x00, 0x00, 0x00,                                      // current
                    0x00, 0x01, 0x00, 0x00};                                     // trigger 1
  ASSERT_EQ(b.HandleForTest(1, block, StageTransport::kTcp).pdu[0], 0x10);
  const auto end = SteadyClock::now() + std::chrono::seconds(2);
  while (b.AxisSnapshot(0).moving && SteadyClock::now() < end) {
  }
  EXPECT_EQ(b.AxisSnapshot(0).position_counts, 1000);
  EXPECT_EQ(b.HandleForTest(1, Bytes{0x03, 0x00, 0xCC, 0x00, 0x02}, StageTransport::kTcp).pdu,
            (Bytes{0x03, 4, 0x03, 0xE8, 0x00, 0x00}));
}

TEST(StageRampUnit, TheSameRatesRampInKhzPerSecondAndCrawlInSeconds) {
  SimControl control;
  StageSimConfig khz = NoEndpoints();
  StageSimConfig seconds = NoEndpoints();
  for (auto& axis : seconds.axes) axis.ramp_unit = SimRampUnit::kSeconds;
  StageSimulator fast(khz, control);
  StageSimulator slow(seconds, control);
  // 3000 counts at 10,000 counts/s with brdfd's rates of 1,000,000: in kHz/s that is 10⁶
  // counts/s², a 10 ms ramp, so the move takes ~0.31 s; in s it is a 1,000 s ramp.
  const Bytes block = UpperFirstBlock(3000, 10000, 1'000'000);
  ASSERT_EQ(fast.HandleForTest(2, block, StageTransport::kTcp).pdu[0], 0x10);
  ASSERT_EQ(slow.HandleForTest(2, block, StageTransport::kTcp).pdu[0], 0x10);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_FALSE(fast.AxisSnapshot(1).moving);
  EXPECT_EQ(fast.AxisSnapshot(1).position_counts, 3000);
  EXPECT_TRUE(slow.AxisSnapshot(1).moving);
  // ½ a t² with a = 10 counts/s²: under a count at 0.6 s, 20 counts even at 2 s.
  EXPECT_LT(slow.AxisSnapshot(1).position_counts, 100);
}

TEST(StageRampUnit, ARampShorterThanTheMoveLengthensItByHalfOfEachRamp) {
  SimControl control;
  StageSimConfig c = NoEndpoints();
  c.time_scale.factor = 10;
  for (auto& axis : c.axes) axis.ramp_unit = SimRampUnit::kSeconds;
  StageSimulator stage(c, control);
  // 2000 counts at 1000 counts/s with 1 s ramps: 1 s up (500 counts), 1 s at speed, 1 s down =
  // 3 s simulated (0.3 s real) instead of 2 s without ramps.
  ASSERT_EQ(stage.HandleForTest(1, UpperFirstBlock(2000, 1000, 1000), StageTransport::kTcp).pdu[0],
            0x10);
  const auto start = SteadyClock::now();
  while (stage.AxisSnapshot(0).moving && SteadyClock::now() - start < std::chrono::seconds(3)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const double took_s = std::chrono::duration<double>(SteadyClock::now() - start).count();
  EXPECT_EQ(stage.AxisSnapshot(0).position_counts, 2000);
  EXPECT_GT(took_s, 0.27);  // 2.7 s simulated: more than without ramps (0.2 s real)
  EXPECT_LT(took_s, 1.5);
}

}  // namespace
}  // namespace brdf::sim
