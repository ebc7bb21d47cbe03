#include "core/readings/derive.h"

#include <cmath>
#include <utility>

#include "core/geometry.h"

namespace brdf {
namespace {

std::string Name(const Reading& r) {
  return "reading " + std::to_string(r.id);
}

bool Finite(const Directions& d) {
  return std::isfinite(d.theta_i) && std::isfinite(d.phi_i) && std::isfinite(d.theta_o) &&
         std::isfinite(d.phi_o);
}

void FailAll(SampleQuantities& out, const std::string& why) {
  for (std::string& w : out.why_not) w = why;
}

void Fail(SampleQuantities& out, Quantity q, const std::string& why) {
  out.why_not[static_cast<int>(q)] = why;
}

}  // namespace

ReadingDeriver::ReadingDeriver(double white_reflectance, std::optional<Spectrum> white_spectrum)
    : white_reflectance_(white_reflectance), white_spectrum_(std::move(white_spectrum)) {}

std::optional<SampleQuantities> ReadingDeriver::Fold(const Reading& reading) {
  switch (reading.kind) {
    case ReadingKind::kReference:
      references_[reading.id] = Reference{reading.spectrum, reading.directions.theta_i};
      return std::nullopt;
    case ReadingKind::kDark:
      darks_[reading.id] = reading.spectrum;
      return std::nullopt;
    case ReadingKind::kSample:
      break;
  }
  return Derive(reading);
}

SampleQuantities ReadingDeriver::Derive(const Reading& r) {
  SampleQuantities out;
  out.reading_id = r.id;
  out.directions = r.directions;
  if (!Finite(r.directions) || !IsValid(r.directions, 90.0)) {
    FailAll(out, Name(r) + ": lamp or detector below the surface (θi or θo outside [0°, 90°])");
    return out;
  }
  if (Status valid = ValidateSpectrum(r.spectrum, Name(r)); !valid.ok()) {
    FailAll(out, valid.message());
    return out;
  }
  if (!grid_.has_value()) AdoptGrid(r.spectrum.grid);
  if (!(r.spectrum.grid == *grid_)) {
    FailAll(out, Name(r) + ": its wavelength grid differs from the session's first sample reading");
    return out;
  }
  const Result<const Spectrum*> dark = DarkOf(r);
  if (!dark.ok()) {
    FailAll(out, dark.status().message());
    return out;
  }
  std::vector<double>& radiance = out.values[static_cast<int>(Quantity::kRadiance)];
  radiance = r.spectrum.values;
  if (*dark != nullptr) {
    for (std::size_t b = 0; b < radiance.size(); ++b) radiance[b] -= (*dark)->values[b];
  }
  DeriveReflectanceAndBrdf(r, *dark, out);
  return out;
}

void ReadingDeriver::AdoptGrid(const WavelengthGrid& grid) {
  grid_ = grid;
  if (!white_spectrum_.has_value()) return;
  Result<Spectrum> on_grid = Resample(*white_spectrum_, *grid_);
  if (!on_grid.ok()) {
    on_grid = InvalidArgument(
        "the white standard's ρw spectrum (" + std::to_string(white_spectrum_->grid.start_nm) +
        "–" + std::to_string(white_spectrum_->grid.last_nm()) +
        " nm) does not cover the session's grid: " + on_grid.status().message());
  }
  white_on_grid_ = std::move(on_grid);
}

Result<const Spectrum*> ReadingDeriver::DarkOf(const Reading& r) const {
  if (!r.dark_id.has_value()) return static_cast<const Spectrum*>(nullptr);
  auto it = darks_.find(*r.dark_id);
  const std::string which = Name(r) + ": its dark reading " + std::to_string(*r.dark_id);
  if (it == darks_.end()) return InvalidArgument(which + " is not a dark reading of this session");
  if (!(it->second.grid == r.spectrum.grid)) {
    return InvalidArgument(which + " is on another wavelength grid");
  }
  if (Status valid = ValidateSpectrum(it->second, "dark reading " + std::to_string(*r.dark_id));
      !valid.ok()) {
    return InvalidArgument(Name(r) + ": " + valid.message());
  }
  return &it->second;
}

void ReadingDeriver::DeriveReflectanceAndBrdf(const Reading& r, const Spectrum* dark,
                                              SampleQuantities& out) const {
  const Reference* ref = nullptr;
  if (r.reference_id.has_value()) {
    auto it = references_.find(*r.reference_id);
    if (it != references_.end()) ref = &it->second;
  }
  if (ref == nullptr) {
    const std::string why = r.reference_id.has_value()
                                ? Name(r) + ": its reference reading " +
                                      std::to_string(*r.reference_id) +
                                      " is not a reference reading of this session"
                                : Name(r) + ": it names no reference reading";
    Fail(out, Quantity::kReflectance, why);
    Fail(out, Quantity::kBrdf, why);
    return;
  }
  Result<Spectrum> reflectance = dark != nullptr ? Reflectance(r.spectrum, ref->spectrum, *dark)
                                                 : Reflectance(r.spectrum, ref->spectrum);
  if (!reflectance.ok()) {
    Fail(out, Quantity::kReflectance, Name(r) + ": " + reflectance.status().message());
    Fail(out, Quantity::kBrdf, Name(r) + ": " + reflectance.status().message());
    return;
  }
  if (white_on_grid_.has_value() && !white_on_grid_->ok()) {
    Fail(out, Quantity::kBrdf, Name(r) + ": " + white_on_grid_->status().message());
    out.values[static_cast<int>(Quantity::kReflectance)] = std::move(reflectance->values);
    return;
  }
  Result<Spectrum> brdf =
      white_on_grid_.has_value()
          ? BrdfFromReflectance(*reflectance, **white_on_grid_, ref->theta_i, r.directions.theta_i)
          : BrdfFromReflectance(*reflectance, white_reflectance_, ref->theta_i,
                                r.directions.theta_i);
  out.values[static_cast<int>(Quantity::kReflectance)] = std::move(reflectance->values);
  if (!brdf.ok()) {
    Fail(out, Quantity::kBrdf, Name(r) + ": " + brdf.status().message());
    return;
  }
  out.values[static_cast<int>(Quantity::kBrdf)] = std::move(brdf->values);
}

}  // namespace brdf
