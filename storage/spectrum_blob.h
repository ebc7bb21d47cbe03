// The on-disk form of a spectrum: a BLOB of little-endian IEEE-754 float64 values, one per band,
// in wavelength order. Fixed byte order so a database file copied between machines (or read by
// Python: numpy.frombuffer(blob, "<f8")) means the same thing everywhere.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/status.h"

namespace brdf::storage {

inline constexpr std::size_t kSpectrumBytesPerValue = 8;

std::vector<std::uint8_t> EncodeSpectrum(std::span<const double> values);

// kInvalidArgument when the BLOB does not hold exactly `expected_count` values.
Result<std::vector<double>> DecodeSpectrum(std::span<const std::uint8_t> blob,
                                           std::size_t expected_count);

}  // namespace brdf::storage
