// A virtual sample's reflectance as data: a named sum of lobes (lobe.h),
//   f(ωi, ωo, λ) = Σ f_lobe(ωi, ωo, λ)   in sr⁻¹,
// evaluated for directions in the sample frame (docs/geometry.md). brdf-sim's meter draws its
// readings from it and `brdf-sim truth` prints it; material_reader.h reads one from a file, and
// builtin_samples.h builds the simulator's compiled-in samples as materials. Pure; immutable and
// so safe to share between threads.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/material/lobe.h"
#include "core/pose.h"
#include "core/wavelength_grid.h"

namespace brdf::material {

class Material {
 public:
  Material() = default;
  Material(std::string name, std::vector<std::shared_ptr<const Lobe>> lobes);

  const std::string& name() const { return name_; }
  const std::vector<std::shared_ptr<const Lobe>>& lobes() const { return lobes_; }
  // True when any lobe is anisotropic.
  bool anisotropic() const;

  // f(λ) in sr⁻¹ for directions in degrees. 0 when either direction is below the surface
  // (θ outside [0°, 90°]) or an angle or the wavelength is not finite, as core/analytic_brdf.h.
  double Evaluate(const Directions& d, double wavelength_nm) const;
  // One value per band of `grid` (the span overload writes min(out.size(), grid.count) values).
  void EvaluateSpectrum(const Directions& d, const WavelengthGrid& grid,
                        std::span<double> out) const;
  std::vector<double> EvaluateSpectrum(const Directions& d, const WavelengthGrid& grid) const;

  // f at each wavelength of `nm` into `out` (the same length) for unit vectors in the sample
  // frame; 0 when either has z < 0.
  void Evaluate(const DirectionPair& d, std::span<const double> nm, std::span<double> out) const;

 private:
  std::string name_;
  std::vector<std::shared_ptr<const Lobe>> lobes_;
};

}  // namespace brdf::material
