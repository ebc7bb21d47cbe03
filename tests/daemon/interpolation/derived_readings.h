// The three quantities of a sample reading recomputed from the raw spectra that StreamReadings
// returns, as docs/geometry.md defines them: what the interpolation tests compare brdfd's
// answers with (its provenance, and interpolators of core/interp over the same readings).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/interp/interpolator.h"
#include "core/pose.h"

namespace brdf::testing {

struct DerivedReading {
  std::vector<double> radiance, reflectance, brdf;
  IsoDirection iso;
  Directions directions;
};

// Radiance I − D, reflectance (I − D) / (I0 − D) and BRDF R · ρw / π · cos θi,ref / cos θi of
// sample reading `r` (ρw = 0.99, the simulator's white), from the reference and dark it names
// (both must be in `by_id`).
DerivedReading DeriveReading(const v1::Reading& r,
                             const std::map<std::int64_t, v1::Reading>& by_id);

// The sample readings of `readings` (in id order) as core/interp samples of their BRDF at their
// (θi, θo, φ): the set brdfd's index holds for an isotropic session's BRDF.
std::shared_ptr<interp::SampleSet> BrdfSampleSet(const std::vector<v1::Reading>& readings);

}  // namespace brdf::testing
