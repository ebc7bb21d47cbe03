#include "daemon/index/build.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>

#include "core/interp/octant/octant.h"
#include "daemon/index/cache.h"

namespace brdf::daemon {

bool IndexKey::operator==(const IndexKey& o) const {
  return std::tie(quantity, method, axis_scale, mirror_phi, reciprocity, coordinates, trend) ==
         std::tie(o.quantity, o.method, o.axis_scale, o.mirror_phi, o.reciprocity, o.coordinates,
                  o.trend);
}

IndexKey MakeIndexKey(Quantity quantity, interp::Method method, const interp::Options& options) {
  IndexKey key{quantity,
               method,
               options.axis_scale,
               options.mirror_phi,
               options.reciprocity,
               options.coordinates,
               options.trend};
  if (std::all_of(key.axis_scale.begin(), key.axis_scale.end(), [](double s) { return s == 1; })) {
    key.axis_scale.clear();
  }
  return key;
}

namespace {

const char* AxisNames(const interp::Options& options, int dims) {
  if (dims == 4) return "θi, φi, θo, φo";
  return options.coordinates == interp::Coordinates::kHalfDifference ? "θh·cos φd, θh·sin φd, θd"
                                                                     : "θi, θo, φ";
}

}  // namespace

Status CheckIndexOptions(const interp::Options& options, int dims, std::int64_t session) {
  if (dims == 4 && options.coordinates == interp::Coordinates::kHalfDifference) {
    return InvalidArgument(
        "options.coordinates: half/difference angles are only for isotropic sessions; session " +
        std::to_string(session) +
        " is anisotropic (its BRDF depends on the azimuth the half/difference angles drop): "
        "interpolate it in incidence coordinates (leave options.coordinates unset or INCIDENCE)");
  }
  if (dims == 4 && options.trend == interp::Trend::kBivariate) {
    return InvalidArgument(
        "options.trend: the bivariate trend is only for isotropic sessions; session " +
        std::to_string(session) +
        " is anisotropic (its BRDF is not a function of θh and θd alone): leave options.trend "
        "unset or NONE");
  }
  if (!options.axis_scale.empty()) {
    if (static_cast<int>(options.axis_scale.size()) != dims) {
      return InvalidArgument("options.axis_scale: give " + std::to_string(dims) +
                             " values (one per axis, " + AxisNames(options, dims) +
                             ") or none, not " + std::to_string(options.axis_scale.size()));
    }
    for (std::size_t i = 0; i < options.axis_scale.size(); ++i) {
      const double s = options.axis_scale[i];
      if (!std::isfinite(s) || s <= 0) {
        return InvalidArgument("options.axis_scale[" + std::to_string(i) +
                               "]: must be a finite number > 0 (got " + std::to_string(s) + ")");
      }
    }
  }
  if (dims == 4 && options.mirror_phi) {
    return InvalidArgument("options.mirror_phi: only for isotropic sessions; session " +
                           std::to_string(session) +
                           " is anisotropic (mirroring φ is not a symmetry of its sample)");
  }
  if (dims == 4 && options.reciprocity) {
    return InvalidArgument("options.reciprocity: only for isotropic sessions; session " +
                           std::to_string(session) + " is anisotropic");
  }
  return Status::Ok();
}

Status CheckHasSamples(const interp::SampleSet* samples, Quantity quantity, std::size_t skipped,
                       const std::string& skipped_detail, std::int64_t session) {
  if (samples != nullptr && samples->size() > 0) return Status::Ok();
  std::string message = "session " + std::to_string(session) + " has no sample reading with a " +
                        QuantityName(quantity) + " yet";
  if (skipped > 0) {
    message += " (" + std::to_string(skipped) + " left out; the first: " + skipped_detail + ")";
  } else {
    message += "; interpolate once the session has taken sample readings";
  }
  return FailedPrecondition(message);
}

Result<MadeIndex> MakeIndex(std::shared_ptr<const interp::SampleSet> samples, interp::Method method,
                            const interp::Options& options, const IndexSnapshot* stale,
                            std::int64_t session) {
  // Extending fails only if the set did not grow by Add (it always does); then a fresh build.
  // Only the octant method in incidence coordinates extends: a half/difference index is no
  // OctantInterpolator (it wraps one over the images of the samples, made in blocks) and is
  // rebuilt, and so is one over a trend's residuals (the trend is refitted to every reading); the
  // key keeps the coordinates and trends apart, so `stale` is always one of the same kind.
  const auto* base =
      stale != nullptr ? dynamic_cast<const interp::OctantInterpolator*>(stale->interpolator.get())
                       : nullptr;
  if (base != nullptr) {
    Result<std::unique_ptr<interp::OctantInterpolator>> grown =
        interp::OctantInterpolator::Extend(*base, samples);
    if (grown.ok()) {
      // An extension that folded everything into a fresh tree counts as a build.
      const bool kept_tree = (*grown)->tail_size() != 0;
      return MadeIndex{std::move(grown).value(), kept_tree};
    }
  }
  const std::size_t count = samples->size();
  Result<std::unique_ptr<interp::Interpolator>> made =
      interp::MakeInterpolator(method, std::move(samples), options);
  if (!made.ok()) {
    return FailedPrecondition("session " + std::to_string(session) + ": cannot build the " +
                              interp::MethodName(method) + " index over its " +
                              std::to_string(count) +
                              " sample reading(s): " + made.status().message() +
                              "; try another method or wait for more readings");
  }
  return MadeIndex{std::move(made).value(), false};
}

std::size_t SetBytes(const interp::SampleSet& set) {
  return sizeof(interp::SampleSet) + set.HeapBytes();
}

}  // namespace brdf::daemon
