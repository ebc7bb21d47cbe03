#include "core/export/merl/reader.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <string>

namespace brdf::exports {
namespace {

std::uint64_t LittleEndianBits(const char* p, int bytes) {
  std::uint64_t v = 0;
  for (int b = 0; b < bytes; ++b) {
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(p[b])) << (8 * b);
  }
  return v;
}

}  // namespace

Result<MerlTable> ParseMerl(std::string_view bytes) {
  if (bytes.size() < 12) {
    return InvalidArgument("MERL file: " + std::to_string(bytes.size()) +
                           " bytes, too short for the three dimensions");
  }
  std::int64_t n = 1;
  std::string dims;
  for (int d = 0; d < 3; ++d) {
    const auto dim = static_cast<std::int32_t>(
        static_cast<std::uint32_t>(LittleEndianBits(bytes.data() + 4 * d, 4)));
    n *= dim;
    dims += (d ? " × " : "") + std::to_string(dim);
  }
  if (n != static_cast<std::int64_t>(kMerlCells)) {
    return InvalidArgument("MERL file: dimensions " + dims + " do not match 90 × 90 × 180");
  }
  if (bytes.size() != kMerlFileBytes) {
    return InvalidArgument("MERL file: " + std::to_string(bytes.size()) + " bytes instead of " +
                           std::to_string(kMerlFileBytes) + " (12 + 3 · 8 · 90 · 90 · 180)");
  }
  MerlTable table;
  const char* p = bytes.data() + 12;
  for (std::size_t i = 0; i < table.stored.size(); ++i, p += 8) {
    table.stored[i] = std::bit_cast<double>(LittleEndianBits(p, 8));
  }
  return table;
}

Rgb LookupMerl(const MerlTable& table, const Directions& d) {
  constexpr double kDegToRad = std::numbers::pi / 180.0;
  const HalfDiff hd = StdToHalfDiff(d.theta_i * kDegToRad, d.phi_i * kDegToRad,
                                    d.theta_o * kDegToRad, d.phi_o * kDegToRad);
  const std::size_t ind =
      MerlIndex(MerlThetaHalfIndex(hd.theta_half), MerlThetaDiffIndex(hd.theta_diff),
                MerlPhiDiffIndex(hd.phi_diff));
  return Rgb{table.stored[ind] * kMerlRedScale, table.stored[ind + kMerlCells] * kMerlGreenScale,
             table.stored[ind + 2 * kMerlCells] * kMerlBlueScale};
}

}  // namespace brdf::exports
