#include "storage/spectrum_blob.h"

#include <bit>
#include <string>

namespace brdf::storage {

std::vector<std::uint8_t> EncodeSpectrum(std::span<const double> values) {
  std::vector<std::uint8_t> out;
  out.reserve(values.size() * kSpectrumBytesPerValue);
  for (double v : values) {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    for (std::size_t b = 0; b < kSpectrumBytesPerValue; ++b) {
      out.push_back(static_cast<std::uint8_t>(bits >> (8 * b)));
    }
  }
  return out;
}

Result<std::vector<double>> DecodeSpectrum(std::span<const std::uint8_t> blob,
                                           std::size_t expected_count) {
  if (blob.size() != expected_count * kSpectrumBytesPerValue) {
    return InvalidArgument("spectrum BLOB holds " + std::to_string(blob.size()) + " bytes but " +
                           std::to_string(expected_count) + " bands need " +
                           std::to_string(expected_count * kSpectrumBytesPerValue));
  }
  std::vector<double> values(expected_count);
  for (std::size_t i = 0; i < expected_count; ++i) {
    std::uint64_t bits = 0;
    for (std::size_t b = 0; b < kSpectrumBytesPerValue; ++b) {
      bits |= static_cast<std::uint64_t>(blob[i * kSpectrumBytesPerValue + b]) << (8 * b);
    }
    values[i] = std::bit_cast<double>(bits);
  }
  return values;
}

}  // namespace brdf::storage
