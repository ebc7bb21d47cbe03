#include "core/interp/octant.h"

#include <algorithm>
#include <array>
#include <limits>

#include "core/interp/barycentric.h"
#include "core/interp/kd_tree.h"
#include "core/interp/octant_cube.h"
#include "core/interp/point_cloud.h"

namespace brdf::interp {

struct OctantInterpolator::Impl {
  Impl(std::shared_ptr<const SampleSet> s, PointCloud c)
      : samples(std::move(s)), cloud(std::move(c)), tree(cloud) {}

  // Steps 1–4 up to the blend: the query in scaled space, the winners, the simplex and weights.
  // False (and `blend` untouched) for an invalid query. `prefetch_all`: start fetching every
  // winner's spectrum right after the search (for a blend that follows at once); otherwise only
  // the chosen vertices' spectra are fetched, once the simplex is known (for a blend that comes
  // one query later, SpectraAt).
  bool Blend(std::span<const double> query, OctantBlend& blend, bool prefetch_all = true) const {
    const int d = cloud.dims;
    if (!ValidQuery(query, d)) return false;
    std::array<double, kMaxDims> p{};
    cloud.ScaleQuery(query, p);
    OrthantWinners winners;
    tree.NearestPerOrthant(p.data(), winners);
    // Start fetching the winners' spectra now: the blend uses 4 or 5 of them, and the fetch (from
    // main memory, for large sets) overlaps with the choice of the simplex.
    const int orthants = 1 << d;
    if (prefetch_all) {
      for (int o = 0; o < orthants; ++o) {
        const std::uint32_t rank = winners.rank[static_cast<std::size_t>(o)];
        if (rank != kNoPoint) PrefetchSpectrum(samples->spectrum(cloud.sample[rank]));
      }
    }
    blend = FindOctantBlendFast(winners, std::span(p.data(), static_cast<std::size_t>(d)), d);
    if (!prefetch_all && blend.status == InterpStatus::kOk) {
      for (int k = 0; k <= d; ++k) {
        PrefetchSpectrum(samples->spectrum(cloud.sample[blend.rank[static_cast<std::size_t>(k)]]));
      }
    }
    return true;
  }

  // BlendOctantSpectrum for a blend whose spectra were prefetched already.
  void BlendFetched(const OctantBlend& blend, std::span<double> out) const {
    const auto vertex_count = static_cast<std::size_t>(cloud.dims + 1);
    std::array<const double*, kMaxDims + 1> spectra{};
    for (std::size_t k = 0; k < vertex_count; ++k) {
      spectra[k] = samples->spectrum(cloud.sample[blend.rank[k]]).data();
    }
    BlendSpectra(std::span(blend.weight.data(), vertex_count),
                 std::span(spectra.data(), vertex_count), out);
  }

  // The part of a caller's buffer that receives the spectrum (never more than bands() values).
  std::span<double> Bands(std::span<double> spectrum) const {
    return spectrum.first(std::min(spectrum.size(), static_cast<std::size_t>(samples->bands())));
  }

  std::shared_ptr<const SampleSet> samples;
  PointCloud cloud;  // before `tree`, which points into it
  KdTree tree;
};

OctantInterpolator::OctantInterpolator(std::unique_ptr<const Impl> impl) : impl_(std::move(impl)) {}
OctantInterpolator::~OctantInterpolator() = default;

Result<std::unique_ptr<OctantInterpolator>> OctantInterpolator::Create(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (samples == nullptr) return InvalidArgument("octant interpolator: no sample set (null)");
  Result<PointCloud> cloud = BuildPointCloud(*samples, options);
  if (!cloud.ok()) return cloud.status().WithContext("octant interpolator");
  auto impl = std::make_unique<const Impl>(std::move(samples), std::move(cloud).value());
  return std::unique_ptr<OctantInterpolator>(new OctantInterpolator(std::move(impl)));
}

int OctantInterpolator::dims() const {
  return impl_->cloud.dims;
}

int OctantInterpolator::bands() const {
  return impl_->samples->bands();
}

Interpolation OctantInterpolator::Evaluate(std::span<const double> query) const {
  OctantBlend blend;
  if (!impl_->Blend(query, blend)) {
    return InvalidQueryAnswer(Method::kOctant, InterpStatus::kEmptyOctant, query, dims());
  }
  return OctantInterpolation(impl_->cloud, *impl_->samples, blend);
}

InterpStatus OctantInterpolator::SpectrumAt(std::span<const double> query,
                                            std::span<double> spectrum) const {
  OctantBlend blend;
  if (!impl_->Blend(query, blend)) return InterpStatus::kEmptyOctant;
  if (blend.status == InterpStatus::kOk) {
    BlendOctantSpectrum(impl_->cloud, *impl_->samples, blend, impl_->Bands(spectrum));
  }
  return blend.status;
}

void OctantInterpolator::SpectraAt(std::span<const double> queries,
                                   std::span<InterpStatus> statuses,
                                   std::span<double> spectra) const {
  const std::size_t n = statuses.size();
  if (n == 0) return;
  const auto d = static_cast<std::size_t>(dims());
  const std::size_t bands = spectra.size() / n;
  const Impl& impl = *impl_;
  // Query i is searched (its winners' spectra prefetched) before query i − 1 is blended.
  OctantBlend previous;
  for (std::size_t i = 0; i <= n; ++i) {
    OctantBlend blend;
    if (i < n) {
      if (!impl.Blend(queries.subspan(i * d, d), blend, /*prefetch_all=*/false)) {
        blend.status = InterpStatus::kEmptyOctant;
      }
      statuses[i] = blend.status;
    }
    if (i > 0) {
      const std::span<double> row = spectra.subspan((i - 1) * bands, bands);
      if (previous.status == InterpStatus::kOk) {
        impl.BlendFetched(previous, impl.Bands(row));
      } else {
        std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
      }
    }
    previous = blend;
  }
}

OctantResult OctantInterpolator::EvaluateInto(std::span<const double> query,
                                              std::span<double> spectrum) const {
  OctantResult out;
  OctantBlend blend;
  if (!impl_->Blend(query, blend)) {
    out.empty_orthants = (1u << (1 << dims())) - 1u;  // every orthant
    return out;
  }
  out.status = blend.status;
  out.empty_orthants = blend.empty_orthants;
  if (blend.status != InterpStatus::kOk) return out;
  BlendOctantSpectrum(impl_->cloud, *impl_->samples, blend, impl_->Bands(spectrum));
  out.simplex = blend.simplex;
  out.vertex_count = dims() + 1;
  for (std::size_t k = 0; k < static_cast<std::size_t>(out.vertex_count); ++k) {
    out.index[k] = impl_->cloud.sample[blend.rank[k]];
    out.weight[k] = blend.weight[k];
  }
  return out;
}

Result<std::unique_ptr<Interpolator>> MakeOctantInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  Result<std::unique_ptr<OctantInterpolator>> r =
      OctantInterpolator::Create(std::move(samples), options);
  if (!r.ok()) return r.status();
  return std::unique_ptr<Interpolator>(std::move(r).value());
}

}  // namespace brdf::interp
