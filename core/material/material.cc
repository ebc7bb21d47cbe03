#include "core/material/material.h"

#include <algorithm>
#include <cmath>

namespace brdf::material {
namespace {

bool AboveSurface(double theta_deg) {
  return theta_deg >= 0.0 && theta_deg <= 90.0;
}

bool Usable(const Directions& d) {
  return std::isfinite(d.theta_i) && std::isfinite(d.phi_i) && std::isfinite(d.theta_o) &&
         std::isfinite(d.phi_o) && AboveSurface(d.theta_i) && AboveSurface(d.theta_o);
}

}  // namespace

Material::Material(std::string name, std::vector<std::shared_ptr<const Lobe>> lobes)
    : name_(std::move(name)), lobes_(std::move(lobes)) {}

bool Material::anisotropic() const {
  return std::any_of(lobes_.begin(), lobes_.end(),
                     [](const auto& lobe) { return lobe->anisotropic(); });
}

void Material::Evaluate(const DirectionPair& d, std::span<const double> nm,
                        std::span<double> out) const {
  std::fill(out.begin(), out.end(), 0.0);
  // cos(90°) in floating point is 6e-17, not 0: a direction at θ = 90° counts as above, as in
  // Evaluate(Directions).
  if (d.cos_i() < 0.0 || d.cos_o() < 0.0) return;
  for (const auto& lobe : lobes_) lobe->AddTo(d, nm, out);
}

double Material::Evaluate(const Directions& d, double wavelength_nm) const {
  if (!Usable(d) || !std::isfinite(wavelength_nm)) return 0.0;
  double out = 0.0;
  Evaluate(ToVectors(d), std::span<const double>(&wavelength_nm, 1), std::span<double>(&out, 1));
  return out;
}

void Material::EvaluateSpectrum(const Directions& d, const WavelengthGrid& grid,
                                std::span<double> out) const {
  const std::size_t n = std::min(out.size(), grid.count);
  const std::span<double> head = out.first(n);
  if (!Usable(d)) {
    std::fill(head.begin(), head.end(), 0.0);
    return;
  }
  std::vector<double> nm(n);
  for (std::size_t k = 0; k < n; ++k) nm[k] = grid.at(k);
  Evaluate(ToVectors(d), nm, head);
}

std::vector<double> Material::EvaluateSpectrum(const Directions& d,
                                               const WavelengthGrid& grid) const {
  std::vector<double> out(grid.count);
  EvaluateSpectrum(d, grid, out);
  return out;
}

}  // namespace brdf::material
