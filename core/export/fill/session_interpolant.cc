#include "core/export/fill/session_interpolant.h"

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/export/number_text.h"
#include "core/fit/models.h"

namespace brdf::exports {
namespace {

// Retro-reflection f(θ, θ, 0) of a Cook-Torrance fit (band means of kd, ks; shared α, F0): the
// microfacet source when a session has no δ = 0 readings.
RetroProfile RetroFromModel(const fit::CookTorranceFit& model) {
  fit::CookTorranceParams mean = model.band.front();
  mean.kd = mean.ks = 0;
  for (const fit::CookTorranceParams& b : model.band) {
    mean.kd += b.kd / static_cast<double>(model.band.size());
    mean.ks += b.ks / static_cast<double>(model.band.size());
  }
  RetroProfile p;
  for (int t = 0; t <= 89; ++t) {
    const double theta = static_cast<double>(t);
    p.theta_deg.push_back(theta);
    p.value.push_back(fit::CookTorranceBrdf({theta, theta, 0}, mean));
  }
  p.origin = "the fitted Cook-Torrance (GGX) model, α = " + FormatNumber(mean.alpha) +
             " (power iteration on its retro-reflection)";
  return p;
}

// SplitMix64's finaliser (Steele, Lea and Flood 2014): a fixed, well-mixed key per sample index.
std::uint64_t MixedKey(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

std::vector<std::size_t> ModelFitSamples(std::size_t count) {
  std::vector<std::size_t> chosen(count);
  for (std::size_t i = 0; i < count; ++i) chosen[i] = i;
  if (count <= kModelFitSamples) return chosen;
  const auto by_key = [](std::size_t a, std::size_t b) { return MixedKey(a) < MixedKey(b); };
  std::nth_element(chosen.begin(), chosen.begin() + kModelFitSamples, chosen.end(), by_key);
  chosen.resize(kModelFitSamples);
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

Result<fit::CookTorranceFit> FitSampleModel(const interp::SampleSet& samples,
                                            const WavelengthGrid& grid, const CallContext& ctx) {
  fit::Observations data(grid);
  for (const std::size_t i : ModelFitSamples(samples.size())) {
    const std::span<const double> c = samples.coords(i);
    if (Status st = data.Add(IsoDirection{c[0], c[1], c[2]}, samples.spectrum(i)); !st.ok()) {
      return st.WithContext("reading " + std::to_string(samples.id(i)));
    }
  }
  return fit::FitCookTorrance(data, {}, ctx);
}

InterpolantInfo SessionInterpolant::Info() const {
  return {options.mirror_phi,
          options.reciprocity,
          options.axis_scale,
          chain ? chain->Tally().Json() : std::string(),
          interp::CoordinatesName(options.coordinates),
          interp::TrendName(options.trend)};
}

namespace {

// Joins a thread (if it runs) when asked or on the way out.
class JoinOnExit {
 public:
  explicit JoinOnExit(std::thread& thread) : thread_(thread) {}
  JoinOnExit(const JoinOnExit&) = delete;
  JoinOnExit& operator=(const JoinOnExit&) = delete;
  ~JoinOnExit() { Join(); }
  void Join() const {
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::thread& thread_;
};

// The chain over the parts `in` has: the chosen method, then (kChain) the fallback and the model.
std::unique_ptr<FillChain> MakeChain(const SessionInterpolant& in) {
  std::vector<FillChain::Stage> stages;
  stages.push_back({Provenance::kInterpolated, InterpolatorSource(*in.interpolator)});
  if (in.policy == FillPolicy::kChain) {
    if (in.fallback) stages.push_back({Provenance::kFallback, InterpolatorSource(*in.fallback)});
    stages.push_back({Provenance::kModel, ModelSource(*in.model)});
  }
  return std::make_unique<FillChain>(in.policy, std::move(stages));
}

}  // namespace

Result<SessionInterpolant> BuildSessionInterpolant(std::shared_ptr<const DerivedSamples> derived,
                                                   interp::Method method,
                                                   const interp::Options& options,
                                                   FillPolicy policy, const CallContext& ctx) {
  SessionInterpolant in;
  in.derived = std::move(derived);
  in.method = method;
  in.options = options;
  in.policy = policy;
  BRDF_ASSIGN_OR_RETURN(in.samples, ToSampleSet(*in.derived));
  // The chain's Delaunay fallback is built on a thread of its own while this one builds the
  // chosen method and fits the model: the parts do not depend on each other, and on a large
  // session each takes seconds. Errors come in the chain's order all the same.
  const bool chain = policy == FillPolicy::kChain;
  Result<std::unique_ptr<interp::Interpolator>> fallback = std::unique_ptr<interp::Interpolator>();
  std::thread building;
  if (chain && method != interp::Method::kDelaunay) {
    building = std::thread([&] {
      fallback = interp::MakeInterpolator(interp::Method::kDelaunay, in.samples, options);
    });
  }
  const JoinOnExit join(building);
  Result<std::unique_ptr<interp::Interpolator>> chosen =
      interp::MakeInterpolator(method, in.samples, options);
  if (!chosen.ok()) return chosen.status();
  in.interpolator = std::move(*chosen);
  if (chain) {
    Result<fit::CookTorranceFit> model = FitSampleModel(*in.samples, in.derived->grid, ctx);
    join.Join();
    if (!fallback.ok()) return fallback.status().WithContext("the fill chain's Delaunay fallback");
    in.fallback = std::move(*fallback);
    if (!model.ok()) return model.status().WithContext("the fill chain's model");
    in.model = std::make_shared<const fit::CookTorranceFit>(*std::move(model));
  }
  in.chain = MakeChain(in);
  return in;
}

SessionInterpolant ShareSessionInterpolant(const SessionInterpolant& built) {
  SessionInterpolant in{built.derived, built.samples,      built.method,   built.options,
                        built.policy,  built.interpolator, built.fallback, built.model,
                        nullptr,       built.calibrations};
  in.chain = MakeChain(in);
  return in;
}

Result<RglExport> BuildSessionRgl(const Session& session, const SessionInterpolant& in,
                                  const SessionRglOptions& o, const RunControl& control,
                                  const CallContext& ctx) {
  RglOptions options;
  options.theta_i_count = o.theta_i_count;
  options.sample_res = o.sample_res;
  options.theta_i_max_deg = 0;
  for (const DerivedSample& s : in.derived->samples) {
    options.theta_i_max_deg = std::max({options.theta_i_max_deg, s.iso.theta_i, s.iso.theta_o});
  }
  options.theta_i_max_deg = std::min(options.theta_i_max_deg, 89.0);
  options.description = "brdfd session " + std::to_string(session.id) + " '" + session.name +
                        "', BRDF by " + interp::MethodName(in.method) +
                        (o.rgb ? ", linear sRGB (D65)" : "");
  options.rgb = o.rgb;

  Result<RetroProfile> retro = RetroReflectionFromSamples(*in.derived);
  if (!retro.ok()) {
    if (in.model) {
      retro = RetroFromModel(*in.model);
    } else {
      Result<fit::CookTorranceFit> model = FitSampleModel(*in.samples, in.derived->grid, ctx);
      if (!model.ok()) {
        return model.status().WithContext(retro.status().message() +
                                          "; fitting Cook-Torrance (GGX) instead");
      }
      retro = RetroFromModel(*model);
    }
  }
  // Where the chain has no value (fill policy none), the nearest reading's.
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<interp::Interpolator> nearest,
                        interp::MakeInterpolator(interp::Method::kNearest, in.samples, {}));
  return BuildRgl(in.chain->Source(), InterpolatorSource(*nearest), in.derived->grid, *retro,
                  options, control, ctx);
}

}  // namespace brdf::exports
