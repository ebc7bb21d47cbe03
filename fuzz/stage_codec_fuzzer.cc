// Fuzz target: the rotation stage's register codec (drivers/stage/modbus_codec.h), i.e. how the
// driver turns what a drive answers (status words, feedback positions) into flags and degrees,
// and degrees and speeds into registers. The input supplies the register contents, the profile
// and the axis configuration (any double, NaN and infinities included).
//
// Promises checked: packing and unpacking are inverses in both word orders; a value that
// FitsField reads back unchanged; the status flags follow the masks (IN-POS derived when the
// drive has no such bit); and for an axis that ValidateAxis accepts, every angle within its travel
// converts to counts and back to within half a count.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "drivers/stage/modbus_codec.h"
#include "drivers/stage/register_profile.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {
namespace {

using namespace brdf::drivers::stage;

double Double(ByteReader& in) {
  const std::uint64_t bits = (std::uint64_t{in.U32()} << 32) | in.U32();
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

// Either a plausible value (so validation passes often) or any bit pattern.
double Setting(ByteReader& in, double plausible_scale) {
  const std::uint8_t how = in.Byte();
  if (how < 200) return (static_cast<double>(in.U16()) - 32768.0) * plausible_scale;
  return Double(in);
}

RegisterProfile Profile(std::uint8_t which) {
  switch (which % 3) {
    case 0:
      return RegisterProfile::AzDefault();
    case 1:
      return RegisterProfile::Leadshine();
    default:
      return RegisterProfile::Moons();
  }
}

void CheckPacking(std::int32_t value) {
  for (WordOrder order : {WordOrder::kHighFirst, WordOrder::kLowFirst}) {
    const auto regs = PackInt32(value, order);
    BRDF_FUZZ_CHECK(UnpackInt32(regs[0], regs[1], order) == value, "Pack/Unpack not inverse");
    for (int words : {1, 2}) {
      std::uint16_t out[2] = {0, 0};
      if (FitsField(value, words, true)) {
        EncodeField(value, words, order, std::span(out, static_cast<std::size_t>(words)));
        BRDF_FUZZ_CHECK(
            DecodeSigned(std::span<const std::uint16_t>(out, static_cast<std::size_t>(words)),
                         order) == value,
            "a signed value that fits did not read back: " + std::to_string(value));
      }
      if (FitsField(value, words, false)) {
        EncodeField(value, words, order, std::span(out, static_cast<std::size_t>(words)));
        BRDF_FUZZ_CHECK(
            DecodeUnsigned(std::span<const std::uint16_t>(out, static_cast<std::size_t>(words)),
                           order) == static_cast<std::uint32_t>(value),
            "an unsigned value that fits did not read back: " + std::to_string(value));
      }
    }
  }
}

void CheckStatus(std::uint32_t word, const StatusBits& bits) {
  const StatusFlags f = DecodeStatus(word, bits);
  BRDF_FUZZ_CHECK(f.alarm == ((word & bits.alarm) != 0), "alarm flag does not follow its mask");
  BRDF_FUZZ_CHECK(f.moving == ((word & bits.moving) != 0), "moving flag does not follow its mask");
  if (bits.in_position == 0) {
    BRDF_FUZZ_CHECK(f.in_position == (!f.moving && !f.alarm), "derived IN-POS is wrong");
  }
  if (MoveComplete(f)) BRDF_FUZZ_CHECK(!f.alarm && !f.moving, "a move completed in alarm");
}

}  // namespace

int FuzzStageCodec(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  const RegisterProfile profile = Profile(in.Byte());
  BRDF_FUZZ_CHECK(ValidateProfile(profile).ok(), "a built-in profile does not validate");

  // What the drive answered: status word and feedback position registers.
  std::vector<std::uint16_t> status_regs(static_cast<std::size_t>(profile.status.words));
  for (auto& r : status_regs) r = in.U16();
  std::vector<std::uint16_t> position_regs(
      static_cast<std::size_t>(profile.feedback_position.words));
  for (auto& r : position_regs) r = in.U16();

  const std::uint32_t status = DecodeUnsigned(status_regs, profile.word_order);
  CheckStatus(status, profile.status_bits);
  StatusBits fuzzed_bits{in.U32(), in.U32(), in.U32(), in.U32(), in.U32()};
  CheckStatus(status, fuzzed_bits);

  const std::int32_t counts = DecodeSigned(position_regs, profile.word_order);
  CheckPacking(counts);
  CheckPacking(static_cast<std::int32_t>(in.U32()));

  AxisConfig axis;
  axis.present = true;
  axis.unit_id = 1 + in.Byte() % 247;
  axis.counts_per_degree = Setting(in, 0.01);
  axis.zero_offset_counts = static_cast<std::int32_t>(in.U32());
  axis.min_deg = Setting(in, 0.01);
  axis.max_deg = Setting(in, 0.01);
  axis.speed_deg_s = Setting(in, 0.01);
  const double angle = Setting(in, 0.01);

  // Whatever the configuration, conversion must not misbehave (no UB on huge or NaN values).
  (void)CountsToDegrees(counts, axis.counts_per_degree, axis.zero_offset_counts);
  (void)DegreesToCounts(angle, axis.counts_per_degree, axis.zero_offset_counts);
  (void)SpeedToRegister(axis.speed_deg_s, axis.counts_per_degree, profile.speed_scale);

  if (ValidateAxis(drivers::Axis::kAlpha, axis, profile).ok()) {
    // Any angle within the travel limits (the fuzzed one, clamped).
    double deg = std::isfinite(angle) ? angle : axis.min_deg;
    deg = std::min(std::max(deg, axis.min_deg), axis.max_deg);
    const Result<std::int32_t> c =
        DegreesToCounts(deg, axis.counts_per_degree, axis.zero_offset_counts);
    BRDF_FUZZ_CHECK(c.ok(), "an angle within a validated axis' travel does not convert: " +
                                std::to_string(deg) + "°: " + c.status().ToString());
    BRDF_FUZZ_CHECK(FitsField(*c, profile.position.words, true),
                    "an angle within a validated axis' travel does not fit the register");
    const double back = CountsToDegrees(*c, axis.counts_per_degree, axis.zero_offset_counts);
    const double half_count = 0.5 / axis.counts_per_degree;
    BRDF_FUZZ_CHECK(std::abs(back - deg) <= half_count * (1 + 1e-5) + 1e-12 * std::abs(deg),
                    "degrees -> counts -> degrees moved by more than half a count: " +
                        std::to_string(deg) + " -> " + std::to_string(back));
    const Result<std::int32_t> speed =
        SpeedToRegister(axis.speed_deg_s, axis.counts_per_degree, profile.speed_scale);
    BRDF_FUZZ_CHECK(speed.ok() && *speed > 0, "a validated axis speed does not convert");
  }
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzStageCodec)
