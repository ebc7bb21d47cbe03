// Shared by the export tests: the CIE tables from colord-data, small CSV parsing.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/colorimetry.h"
#include "core/export/session_data.h"
#include "core/export/spectral_rgb.h"

namespace brdf::exports::testing {

// The whole file, or "" when it cannot be read.
std::string ReadFile(const std::string& path);

// CIE 1931 2° CMFs and D65 from /usr/share/colord (Debian's colord-data). Fails the test (with
// what to install) when they are missing.
struct CieTables {
  ColorMatchingFunctions cmf;
  Spectrum d65;
};
CieTables LoadCie();
SpectralRgbWeights D65Weights(const WavelengthGrid& grid);

// Lines of `text` that do not start with '#'; each split at commas.
std::vector<std::vector<std::string>> CsvRows(const std::string& text);
// Lines that start with '#'.
std::vector<std::string> CommentLines(const std::string& text);

// The synthetic paper-grid session of a paint-like sample as BRDF samples in 11 bands (380 nm
// every 40 nm), and the same as an interpolation sample set. Fails the test (nullopt) when a step
// fails.
struct PaintGridSamples {
  DerivedSamples derived;
  std::shared_ptr<const interp::SampleSet> set;
};
std::optional<PaintGridSamples> PaintLikeGridSamples();

}  // namespace brdf::exports::testing
