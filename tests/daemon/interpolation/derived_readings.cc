#include "tests/daemon/interpolation/derived_readings.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace brdf::testing {

DerivedReading DeriveReading(const v1::Reading& r,
                             const std::map<std::int64_t, v1::Reading>& by_id) {
  DerivedReading d;
  d.iso = {r.iso().theta_i(), r.iso().theta_o(), r.iso().phi()};
  d.directions = {r.directions().theta_i(), r.directions().phi_i(), r.directions().theta_o(),
                  r.directions().phi_o()};
  const v1::Reading& white = by_id.at(r.reference_id());
  const v1::Reading* dark = r.dark_id() != 0 ? &by_id.at(r.dark_id()) : nullptr;
  const double cos_ratio = std::cos(white.directions().theta_i() * std::numbers::pi / 180) /
                           std::cos(r.directions().theta_i() * std::numbers::pi / 180);
  for (int b = 0; b < r.radiance_size(); ++b) {
    const double dk = dark ? dark->radiance(b) : 0.0;
    const double i = r.radiance(b) - dk;
    const double i0 = white.radiance(b) - dk;
    d.radiance.push_back(i);
    d.reflectance.push_back(i / i0);
    d.brdf.push_back(i / i0 * 0.99 / std::numbers::pi * cos_ratio);
  }
  return d;
}

std::shared_ptr<interp::SampleSet> BrdfSampleSet(const std::vector<v1::Reading>& readings) {
  std::map<std::int64_t, v1::Reading> by_id;
  for (const v1::Reading& r : readings) by_id[r.id()] = r;
  std::shared_ptr<interp::SampleSet> set;
  for (const auto& [id, r] : by_id) {
    if (r.kind() != v1::READING_KIND_SAMPLE) continue;
    const DerivedReading d = DeriveReading(r, by_id);
    if (!set) set = std::make_shared<interp::SampleSet>(3, static_cast<int>(d.brdf.size()));
    const double coords[3] = {d.iso.theta_i, d.iso.theta_o, d.iso.phi};
    if (!set->Add(id, coords, d.brdf).ok()) return nullptr;
  }
  return set;
}

}  // namespace brdf::testing
