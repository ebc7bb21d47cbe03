#include "tools/brdf-interp/accuracy_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include "core/analytic_brdf.h"
#include "core/fit/models.h"
#include "core/geometry.h"
#include "core/interp/half_difference.h"
#include "tools/brdf-interp/synthetic_samples.h"
#include "tools/brdf-interp/tool_common.h"

namespace brdf::interp_tool {
namespace {

constexpr double kPeakQuery[3] = {42.5, 42.5, 177.5};
constexpr double kNearPeakThetaHalfDeg = 10.0;

// n random rig poses (see the header) as (θi, θo, φ), through the rig's own kinematics.
std::vector<double> RigPoseQueries(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uniform = [&rng](double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
  };
  std::vector<double> out;
  out.reserve(3 * n);
  while (out.size() < 3 * n) {
    Pose pose;
    pose.alpha = uniform(0, 70);
    pose.beta = uniform(-175, 180);
    pose.delta = uniform(0, 146.25);
    const Directions d = PoseToDirections(pose);
    if (!IsValid(d, 89.999)) continue;
    const IsoDirection iso = ToIsotropic(d);
    out.insert(out.end(), {iso.theta_i, iso.theta_o, iso.phi});
  }
  return out;
}

struct Row {
  std::string method;
  interp::Coordinates coordinates;
  std::vector<interp::InterpStatus> status;
  std::vector<double> spectra;  // queries × bands
  double peak = std::nan("");   // relative error at the peak query
  std::size_t ok = 0;
};

// The same samples with every value replaced by log(max(f, floor_b)), floor_b = 1e-6 of band b's
// largest value (see the header): a linear blend of these, exponentiated, is the log blend.
std::shared_ptr<interp::SampleSet> LogSamples(const interp::SampleSet& set) {
  const auto bands = static_cast<std::size_t>(set.bands());
  std::vector<double> floor(bands, 0.0);
  for (std::size_t i = 0; i < set.size(); ++i) {
    for (std::size_t b = 0; b < bands; ++b) floor[b] = std::max(floor[b], set.spectrum(i)[b]);
  }
  for (double& f : floor) f = f > 0 ? 1e-6 * f : 1e-300;
  auto out = std::make_shared<interp::SampleSet>(set.dims(), set.bands());
  std::vector<double> logs(bands);
  for (std::size_t i = 0; i < set.size(); ++i) {
    for (std::size_t b = 0; b < bands; ++b) {
      logs[b] = std::log(std::max(set.spectrum(i)[b], floor[b]));
    }
    const Status added = out->Add(set.id(i), set.coords(i), logs);
    if (!added.ok()) return nullptr;  // cannot happen: same dims and bands
  }
  return out;
}

// A sample whose BRDF is known: its spectrum at (θi, θo, φ).
struct KnownSample {
  std::string name;
  std::function<void(const IsoDirection&, std::span<double>)> spectrum;
};

KnownSample Analytic(std::string name, AnalyticBrdf brdf, const WavelengthGrid& grid) {
  return {std::move(name), [brdf, grid](const IsoDirection& at, std::span<double> out) {
            brdf.EvaluateSpectrum({at.theta_i, 0, at.theta_o, at.phi}, grid, out);
          }};
}

// The paint's diffuse base under a Cook-Torrance (GGX) lobe with Fresnel and shadowing (see the
// header): not a function of (θh, θd) alone.
KnownSample GlossyCookTorrance(const WavelengthGrid& grid) {
  AnalyticBrdfParams diffuse = AnalyticBrdf::PaintLike().params();
  diffuse.specular_weight = 0;
  const AnalyticBrdf base(diffuse);
  return {"glossy-ct (paint base + Cook-Torrance GGX α 0.1, F0 0.04, ks 4)",
          [base, grid](const IsoDirection& at, std::span<double> out) {
            base.EvaluateSpectrum({at.theta_i, 0, at.theta_o, at.phi}, grid, out);
            const double lobe = 4.0 * fit::CookTorranceSpecular(at, 0.1, 0.04);
            for (double& v : out) v += lobe;
          }};
}

// The sample "measured" at the points; with noise > 0 each reading is scaled by (1 + noise · z),
// z standard normal, one z per reading (a meter's gain noise), seeded.
std::shared_ptr<interp::SampleSet> KnownSamples(const SyntheticPoints& points,
                                                const WavelengthGrid& grid,
                                                const KnownSample& sample, double noise,
                                                std::uint64_t seed) {
  auto set = std::make_shared<interp::SampleSet>(3, static_cast<int>(grid.count));
  std::vector<double> f(grid.count);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::span<const double> c(points.coords.data() + 3 * i, 3);
    sample.spectrum({c[0], c[1], c[2]}, f);
    if (noise > 0) {
      const double gain = 1 + noise * z(rng);
      for (double& v : f) v *= gain;
    }
    if (!set->Add(static_cast<std::int64_t>(i), c, f).ok()) return nullptr;  // same dims, bands
  }
  return set;
}

std::string Percent(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%+.2f %%", 100 * v);
  return b;
}

// The samples --sample names.
Result<std::vector<KnownSample>> SamplesNamed(const std::string& which,
                                              const WavelengthGrid& wavelengths) {
  std::vector<KnownSample> samples;
  if (which == "paint" || which == "both" || which == "all") {
    samples.push_back(
        Analytic("paint (AnalyticBrdf::PaintLike)", AnalyticBrdf::PaintLike(), wavelengths));
  }
  if (which == "glossy" || which == "both" || which == "all") {
    samples.push_back(
        Analytic("glossy (AnalyticBrdf::Glossy)", AnalyticBrdf::Glossy(), wavelengths));
  }
  if (which == "glossy-ct" || which == "all") samples.push_back(GlossyCookTorrance(wavelengths));
  if (samples.empty()) {
    return InvalidArgument("--sample '" + which +
                           "': use paint, glossy, glossy-ct, both (paint and glossy) or all");
  }
  return samples;
}

// How the methods are run: in each coordinate system, and in logs or not.
struct Setup {
  interp::Trend trend = interp::Trend::kNone;
  bool log_blend = false;
  interp::Options incidence, half;
};

Result<Setup> ReadSetup(const AccuracyRequest& request) {
  Setup setup;
  Result<interp::Trend> trend = interp::ParseTrend(request.trend);
  if (!trend.ok()) return trend.status().WithContext("--trend");
  setup.trend = *trend;
  if (request.queries == 0) return InvalidArgument("--queries: give at least one query");
  if (!(request.noise >= 0 && request.noise < 1)) {
    return InvalidArgument("--noise: a relative standard deviation in [0, 1), e.g. 0.01");
  }
  if (request.blend != "linear" && request.blend != "log") {
    return InvalidArgument("--blend '" + request.blend + "': use linear or log");
  }
  setup.log_blend = request.blend == "log";
  setup.incidence.mirror_phi = request.mirror_phi;
  setup.incidence.reciprocity = request.reciprocity;
  setup.incidence.trend = *trend;
  setup.half = setup.incidence;
  setup.half.coordinates = interp::Coordinates::kHalfDifference;
  if (!request.scale.empty()) {
    BRDF_ASSIGN_OR_RETURN(std::vector<double> s, ParseNumberList(request.scale, "--scale"));
    setup.incidence.axis_scale = s;
  }
  if (!request.half_scale.empty()) {
    BRDF_ASSIGN_OR_RETURN(std::vector<double> s,
                          ParseNumberList(request.half_scale, "--half-scale"));
    setup.half.axis_scale = s;
  }
  return setup;
}

void PrintSetup(const AccuracyRequest& request, const Setup& setup, std::size_t grid_points,
                const WavelengthGrid& wavelengths, std::size_t peak_band, std::ostream& out) {
  out << "Paper's rig grid: " << grid_points << " points; " << request.queries
      << " random rig poses (seed " << request.seed << ")"
      << (request.mirror_phi ? "; mirror φ" : "") << (request.reciprocity ? "; reciprocity" : "")
      << "; scales (θi, θo, φ) " << (request.scale.empty() ? "1,1,1" : request.scale)
      << ", (θh·cos φd, θh·sin φd, θd) "
      << (request.half_scale.empty() ? "1,1,1 (default)" : request.half_scale) << "; "
      << (setup.log_blend ? "log blend (floor 1e-6 of each band's largest value)" : "linear blend")
      << (setup.trend == interp::Trend::kBivariate ? "; bivariate trend" : "");
  if (request.noise > 0) out << "; readings × (1 + " << request.noise << " · N(0, 1))";
  out << "\n";
  out << "peak: (" << kPeakQuery[0] << ", " << kPeakQuery[1] << ", " << kPeakQuery[2] << ") at "
      << wavelengths.at(peak_band) << " nm; RMS over the queries every row answered\n";
}

// What the methods are judged against: the sample's spectra at the queries, and its value at the
// peak query's band.
struct Truth {
  std::vector<double> spectra;  // queries × bands
  double peak = 0;
};

Truth TruthOf(const KnownSample& sample, const std::vector<double>& queries, std::size_t bands,
              std::size_t peak_band) {
  const std::size_t n = queries.size() / 3;
  Truth truth;
  truth.spectra.resize(n * bands);
  for (std::size_t q = 0; q < n; ++q) {
    sample.spectrum({queries[3 * q], queries[3 * q + 1], queries[3 * q + 2]},
                    std::span<double>(truth.spectra).subspan(q * bands, bands));
  }
  std::vector<double> peak_spectrum(bands);
  sample.spectrum({kPeakQuery[0], kPeakQuery[1], kPeakQuery[2]}, peak_spectrum);
  truth.peak = peak_spectrum[peak_band];
  return truth;
}

// One method in one coordinate system on the sample's readings (`set`, or `log_set` when the
// blend is in logs): its answers at the queries and its error at the peak.
Result<Row> RunMethod(const char* method, const interp::Options& options, bool log_blend,
                      const std::shared_ptr<interp::SampleSet>& set,
                      const std::shared_ptr<interp::SampleSet>& log_set,
                      const std::vector<double>& queries, std::size_t bands, std::size_t peak_band,
                      double peak_truth) {
  const std::size_t n = queries.size() / 3;
  Row row{method, options.coordinates, std::vector<interp::InterpStatus>(n),
          std::vector<double>(n * bands)};
  const bool in_logs = log_blend && std::string(method) != "nearest";
  BRDF_ASSIGN_OR_RETURN(auto made, MakeNamedInterpolator(method, in_logs ? log_set : set, options));
  made->SpectraAt(queries, row.status, row.spectra);
  for (interp::InterpStatus s : row.status) row.ok += s == interp::InterpStatus::kOk;
  if (in_logs) {
    for (double& v : row.spectra) v = std::exp(v);  // NaN rows stay NaN
  }
  std::vector<double> peak(bands);
  if (made->SpectrumAt(kPeakQuery, peak) == interp::InterpStatus::kOk) {
    if (in_logs) {
      for (double& v : peak) v = std::exp(v);
    }
    row.peak = (peak[peak_band] - peak_truth) / peak_truth;
  }
  return row;
}

// The common set: queries every row answered; and those of them near the peak.
struct CommonQueries {
  std::vector<bool> common, near_peak;
  std::size_t common_count = 0, near_count = 0;
};

CommonQueries CommonOf(const std::vector<Row>& rows, const std::vector<double>& queries) {
  const std::size_t n = queries.size() / 3;
  CommonQueries c{std::vector<bool>(n, true), std::vector<bool>(n, false)};
  for (std::size_t q = 0; q < n; ++q) {
    for (const Row& r : rows) c.common[q] = c.common[q] && r.status[q] == interp::InterpStatus::kOk;
    const double theta_h =
        interp::ToHalfDifference({queries[3 * q], queries[3 * q + 1], queries[3 * q + 2]}).theta_h;
    c.near_peak[q] = c.common[q] && theta_h < kNearPeakThetaHalfDeg;
    c.common_count += c.common[q];
    c.near_count += c.near_peak[q];
  }
  return c;
}

// The row's RMS error over the queries in `use`, relative to the truth's mean there.
double RelativeRms(const Row& r, const std::vector<double>& truth, const std::vector<bool>& use,
                   std::size_t bands) {
  double sum = 0, mean = 0, count = 0;
  for (std::size_t q = 0; q < use.size(); ++q) {
    if (!use[q]) continue;
    for (std::size_t b = 0; b < bands; ++b) {
      const double d = r.spectra[q * bands + b] - truth[q * bands + b];
      sum += d * d;
      mean += truth[q * bands + b];
      count += 1;
    }
  }
  return count == 0 ? std::nan("") : std::sqrt(sum / count) / (mean / count);
}

void PrintTable(const std::string& name, const std::vector<Row>& rows,
                const std::vector<double>& truth, const CommonQueries& c, std::size_t bands,
                std::ostream& out) {
  out << "\n"
      << name << ": " << c.common_count << " common queries, " << c.near_count
      << " of them with θh < " << kNearPeakThetaHalfDeg << "°\n";
  out << "| method | coordinates | ok | RMS | RMS θh<10° | peak |\n|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    char line[256];
    std::snprintf(line, sizeof line, "| %s | %s | %zu | %.2f %% | %.2f %% | %s |\n",
                  r.method.c_str(),
                  r.coordinates == interp::Coordinates::kIncidence ? "θi, θo, φ" : "θh, θd, φd",
                  r.ok, 100 * RelativeRms(r, truth, c.common, bands),
                  100 * RelativeRms(r, truth, c.near_peak, bands),
                  std::isnan(r.peak) ? "failed" : Percent(r.peak).c_str());
    out << line;
  }
}

}  // namespace

int RunAccuracy(const AccuracyRequest& request, std::ostream& out, std::ostream& err) {
  auto fail = [&err](const Status& s) {
    err << "brdf-interp accuracy: " << s.message() << "\n";
    return ExitCodeFor(s);
  };
  const WavelengthGrid wavelengths = WavelengthGrid::Pr650();
  const Result<std::vector<KnownSample>> samples = SamplesNamed(request.sample, wavelengths);
  if (!samples.ok()) return fail(samples.status());
  const Result<Setup> setup = ReadSetup(request);
  if (!setup.ok()) return fail(setup.status());
  Result<SyntheticPoints> grid = PaperGridPoints();
  if (!grid.ok()) return fail(grid.status());
  const std::size_t bands = wavelengths.count;
  const auto peak_band =
      static_cast<std::size_t>(std::lround((550.0 - wavelengths.start_nm) / wavelengths.step_nm));
  const std::vector<double> queries = RigPoseQueries(request.queries, request.seed);
  PrintSetup(request, *setup, grid->size(), wavelengths, peak_band, out);

  for (const KnownSample& sample : *samples) {
    const auto set = KnownSamples(*grid, wavelengths, sample, request.noise, request.seed + 1);
    const auto log_set = setup->log_blend ? LogSamples(*set) : nullptr;
    const Truth truth = TruthOf(sample, queries, bands, peak_band);
    std::vector<Row> rows;
    for (const char* method : {"octant", "delaunay", "nearest"}) {
      for (const interp::Options* o : {&setup->incidence, &setup->half}) {
        Result<Row> row = RunMethod(method, *o, setup->log_blend, set, log_set, queries, bands,
                                    peak_band, truth.peak);
        if (!row.ok()) return fail(row.status());
        rows.push_back(std::move(row).value());
      }
    }
    PrintTable(sample.name, rows, truth.spectra, CommonOf(rows, queries), bands, out);
  }
  return kExitOk;
}

}  // namespace brdf::interp_tool
