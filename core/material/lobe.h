// One term of a material's BRDF: a lobe, f_lobe(ωi, ωo, λ) in sr⁻¹. A material is a sum of lobes
// (material.h); diffuse_lobes.h and glossy_lobes.h hold the kinds a material file can name, and
// docs/materials.md gives each one's formula and source. Pure.
#pragma once

#include <span>
#include <string_view>

#include "core/material/local_frame.h"

namespace brdf::material {

class Lobe {
 public:
  virtual ~Lobe() = default;

  // The lobe's `type` in a material file: "lambert", "oren_nayar", "ggx", "beckmann",
  // "blinn_phong", "retro".
  virtual std::string_view type() const = 0;
  // True when the lobe changes under a rotation about the normal.
  virtual bool anisotropic() const { return false; }

  // Adds the lobe's value at each wavelength of `nm` to `out` (the same length). The material
  // calls it only for directions on or above the surface (cos θ ≥ 0 for both).
  virtual void AddTo(const DirectionPair& d, std::span<const double> nm,
                     std::span<double> out) const = 0;
};

}  // namespace brdf::material
