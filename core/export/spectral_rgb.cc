#include "core/export/spectral_rgb.h"

#include <string>

namespace brdf::exports {

Result<SpectralRgbWeights> SpectralRgbWeights::Make(const WavelengthGrid& grid,
                                                    const Spectrum& illuminant,
                                                    const ColorMatchingFunctions& cmf) {
  if (!grid.valid()) return InvalidArgument("spectral RGB weights: the wavelength grid is invalid");
  SpectralRgbWeights w;
  w.grid_ = grid;
  w.weights_.reserve(grid.count);
  Spectrum impulse{grid, std::vector<double>(grid.count, 0.0)};
  for (std::size_t b = 0; b < grid.count; ++b) {
    impulse.values[b] = 1.0;
    Result<Xyz> xyz = ReflectanceToXyz(impulse, illuminant, cmf);
    if (!xyz.ok()) {
      return xyz.status().WithContext("spectral RGB weights at " + std::to_string(grid.at(b)) +
                                      " nm");
    }
    w.weights_.push_back(XyzToLinearSrgb(*xyz));
    impulse.values[b] = 0.0;
  }
  return w;
}

Rgb SpectralRgbWeights::Apply(std::span<const double> values) const {
  Rgb out;
  const std::size_t n = std::min(values.size(), weights_.size());
  for (std::size_t b = 0; b < n; ++b) {
    out.r += values[b] * weights_[b].r;
    out.g += values[b] * weights_[b].g;
    out.b += values[b] * weights_[b].b;
  }
  return out;
}

}  // namespace brdf::exports
