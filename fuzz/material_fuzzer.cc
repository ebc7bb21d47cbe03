// Fuzz target: a material file (core/material/material_reader.h: ReadMaterial), the TOML a user
// writes and mounts with brdf-sim --material.
//
// Promises checked: a refused file is kInvalidArgument whose message names the file; an accepted
// material has at least one lobe and, at directions across the hemisphere (normal, mirror,
// grazing, back towards the lamp) and wavelengths in and beyond 380–780 nm, a BRDF that is
// finite, not negative and reciprocal.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/material/material_reader.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {

int FuzzMaterial(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = AsText(data, size);
  const Result<material::Material> r = material::ReadMaterial(text, "fuzz.toml", "fuzz");
  if (!r.ok()) {
    BRDF_FUZZ_CHECK(r.status().code() == StatusCode::kInvalidArgument,
                    "refusal is not kInvalidArgument: " + r.status().ToString());
    BRDF_FUZZ_CHECK(r.status().message().find("fuzz.toml") != std::string::npos,
                    "refusal does not name the file: " + r.status().message());
    return 0;
  }
  BRDF_FUZZ_CHECK(!r->lobes().empty(), "accepted material without lobes");
  static constexpr Directions kDirections[] = {
      {0, 0, 0, 0},     {30, 0, 30, 180}, {60, 20, 60, 20},   {89.9, 0, 89.9, 180},
      {90, 0, 90, 180}, {90, 0, 90, 0},   {10, -170, 75, 40}, {45, 90, 20, 270}};
  for (const Directions& d : kDirections) {
    const Directions swapped{d.theta_o, d.phi_o, d.theta_i, d.phi_i};
    for (double nm : {200.0, 380.0, 555.5, 780.0, 2000.0}) {
      const double f = r->Evaluate(d, nm), g = r->Evaluate(swapped, nm);
      BRDF_FUZZ_CHECK(std::isfinite(f) && f >= 0, "BRDF not finite and >= 0: " + std::to_string(f));
      BRDF_FUZZ_CHECK(std::abs(f - g) <= 1e-9 * std::max(1.0, f),
                      "not reciprocal: " + std::to_string(f) + " vs " + std::to_string(g));
    }
  }
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzMaterial)
