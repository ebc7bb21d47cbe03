#include "core/export/session_data.h"

#include <cmath>
#include <unordered_map>
#include <utility>

#include "core/geometry.h"

namespace brdf::exports {

const char* ReadingKindName(ReadingKind kind) {
  switch (kind) {
    case ReadingKind::kSample:
      return "sample";
    case ReadingKind::kReference:
      return "reference";
    case ReadingKind::kDark:
      return "dark";
  }
  return "unknown";
}

double WhiteReflectanceOf(const Session& session) {
  return session.white_reflectance.value_or(kWhiteStandardReflectance);
}

const char* QuantityName(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "radiance";
    case Quantity::kReflectance:
      return "reflectance";
    case Quantity::kBrdf:
      return "brdf";
  }
  return "unknown";
}

const char* QuantityUnit(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "W·m⁻²·sr⁻¹·nm⁻¹";
    case Quantity::kReflectance:
      return "1 (unitless)";
    case Quantity::kBrdf:
      return "sr⁻¹";
  }
  return "";
}

std::string QuantityDefinition(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "spectral radiance I(λ) of the sample, minus the dark reading D(λ) it names (if any), "
             "in W·m⁻²·sr⁻¹·nm⁻¹";
    case Quantity::kReflectance:
      return "reflectance R(λ) = (I(λ) − D(λ)) / (I0(λ) − D(λ)): the sample's radiance over the "
             "white standard's (the reference reading it names), dark subtracted from both when "
             "measured; unitless";
    case Quantity::kBrdf:
      return "BRDF f(λ) = R(λ) · ρw / π · cos θi,ref / cos θi in sr⁻¹, with R = (I − D) / (I0 − "
             "D), "
             "ρw the white standard's reflectance and θi,ref the incidence of the reference "
             "reading";
  }
  return "";
}

Result<Quantity> ParseQuantity(std::string_view name) {
  if (name == "radiance") return Quantity::kRadiance;
  if (name == "reflectance") return Quantity::kReflectance;
  if (name == "brdf") return Quantity::kBrdf;
  return InvalidArgument("unknown quantity '" + std::string(name) +
                         "': use radiance, reflectance or brdf");
}

namespace {

std::string Name(const Reading& r) {
  return "reading " + std::to_string(r.id);
}

bool Finite(const Directions& d) {
  return std::isfinite(d.theta_i) && std::isfinite(d.phi_i) && std::isfinite(d.theta_o) &&
         std::isfinite(d.phi_o);
}

// The quantity for one sample reading, or the reason it cannot be computed.
Result<std::vector<double>> DeriveOne(
    const Reading& r, Quantity quantity, double white,
    const std::unordered_map<std::int64_t, const Reading*>& by_id) {
  const Spectrum& sample = r.spectrum;
  std::optional<Spectrum> dark;
  if (r.dark_id.has_value()) {
    auto it = by_id.find(*r.dark_id);
    if (it == by_id.end() || it->second->kind != ReadingKind::kDark) {
      return InvalidArgument(Name(r) + ": its dark reading " + std::to_string(*r.dark_id) +
                             " is not a dark reading of this session");
    }
    if (!(it->second->spectrum.grid == sample.grid)) {
      return InvalidArgument(Name(r) + ": its dark reading " + std::to_string(*r.dark_id) +
                             " is on another wavelength grid");
    }
    dark = it->second->spectrum;
  }
  if (quantity == Quantity::kRadiance) {
    BRDF_RETURN_IF_ERROR(ValidateSpectrum(sample, Name(r)));
    std::vector<double> v = sample.values;
    if (dark.has_value()) {
      BRDF_RETURN_IF_ERROR(ValidateSpectrum(*dark, "dark reading " + std::to_string(*r.dark_id)));
      for (std::size_t b = 0; b < v.size(); ++b) v[b] -= dark->values[b];
    }
    return v;
  }
  if (!r.reference_id.has_value()) {
    return InvalidArgument(Name(r) + ": it names no reference reading");
  }
  auto it = by_id.find(*r.reference_id);
  if (it == by_id.end() || it->second->kind != ReadingKind::kReference) {
    return InvalidArgument(Name(r) + ": its reference reading " + std::to_string(*r.reference_id) +
                           " is not a reference reading of this session");
  }
  const Reading& ref = *it->second;
  Result<Spectrum> reflectance = dark.has_value() ? Reflectance(sample, ref.spectrum, *dark)
                                                  : Reflectance(sample, ref.spectrum);
  if (!reflectance.ok()) {
    return InvalidArgument(Name(r) + ": " + reflectance.status().message());
  }
  if (quantity == Quantity::kReflectance) return std::move(reflectance->values);
  Result<Spectrum> brdf =
      BrdfFromReflectance(*reflectance, white, ref.directions.theta_i, r.directions.theta_i);
  if (!brdf.ok()) return InvalidArgument(Name(r) + ": " + brdf.status().message());
  return std::move(brdf->values);
}

}  // namespace

Result<DerivedSamples> DeriveSamples(const Session& session, Quantity quantity,
                                     const DeriveOptions& options) {
  const double white = WhiteReflectanceOf(session);
  if (!std::isfinite(white) || white <= 0) {
    return InvalidArgument("session " + std::to_string(session.id) +
                           ": white reflectance ρw = " + std::to_string(white) +
                           " is not a positive number; fix the session's white_reflectance");
  }
  std::unordered_map<std::int64_t, const Reading*> by_id;
  by_id.reserve(session.readings.size());
  for (const Reading& r : session.readings) by_id.emplace(r.id, &r);

  DerivedSamples out;
  out.quantity = quantity;
  out.white_reflectance = white;
  bool have_grid = false;
  std::size_t sample_readings = 0;
  for (const Reading& r : session.readings) {
    if (r.kind != ReadingKind::kSample) continue;
    ++sample_readings;
    auto skip = [&](std::string why) { out.skipped.push_back({r.id, std::move(why)}); };
    if (options.exclude_flagged && r.flagged) {
      skip(Name(r) + ": flagged by the quality policy (left out on request)");
      continue;
    }
    if (!Finite(r.directions) || !IsValid(r.directions, 90.0)) {
      skip(Name(r) + ": lamp or detector below the surface (θi or θo outside [0°, 90°])");
      continue;
    }
    if (have_grid && !(r.spectrum.grid == out.grid)) {
      skip(Name(r) + ": its wavelength grid differs from the session's first sample reading");
      continue;
    }
    Result<std::vector<double>> values = DeriveOne(r, quantity, white, by_id);
    if (!values.ok()) {
      skip(values.status().message());
      continue;
    }
    if (!have_grid) {
      out.grid = r.spectrum.grid;
      have_grid = true;
    }
    out.samples.push_back(
        DerivedSample{r.id, r.directions, ToIsotropic(r.directions), std::move(*values)});
  }
  if (sample_readings == 0) {
    return FailedPrecondition("session " + std::to_string(session.id) +
                              " has no sample readings (empty session): measure it first, or "
                              "pick another session");
  }
  if (out.samples.empty()) {
    return FailedPrecondition("session " + std::to_string(session.id) + ": none of its " +
                              std::to_string(sample_readings) + " sample readings gives a " +
                              QuantityName(quantity) +
                              "; the first: " + out.skipped.front().reason);
  }
  return out;
}

Result<std::shared_ptr<const interp::SampleSet>> ToSampleSet(const DerivedSamples& derived) {
  auto set = std::make_shared<interp::SampleSet>(3, static_cast<int>(derived.grid.count));
  for (const DerivedSample& s : derived.samples) {
    const double coords[3] = {s.iso.theta_i, s.iso.theta_o, s.iso.phi};
    BRDF_RETURN_IF_ERROR(set->Add(s.reading_id, coords, s.values));
  }
  return std::shared_ptr<const interp::SampleSet>(std::move(set));
}

bool HasSeveralDialPositions(const Session& session) {
  const Reading* first = nullptr;
  for (const Reading& r : session.readings) {
    if (r.kind != ReadingKind::kSample) continue;
    if (first == nullptr) {
      first = &r;
    } else if (std::abs(r.pose.gamma - first->pose.gamma) > 1e-9) {
      return true;
    }
  }
  return false;
}

}  // namespace brdf::exports
