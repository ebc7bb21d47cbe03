#include "tools/brdf-interp/demo_command.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/analytic_brdf.h"
#include "core/interp/octant/cube.h"
#include "tools/brdf-interp/synthetic_samples.h"
#include "tools/brdf-interp/tool_common.h"

namespace brdf::interp_tool {
namespace {

std::string Format(const char* format, double a, double b = 0, double c = 0, double d = 0,
                   double e = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, format, a, b, c, d, e);
  return buffer;
}

struct Error {
  double rms = 0, max_abs = 0, mean_truth = 0;
};

Error Compare(const std::vector<double>& value, const std::vector<double>& truth) {
  Error e;
  for (std::size_t b = 0; b < truth.size(); ++b) {
    const double d = value[b] - truth[b];
    e.rms += d * d;
    e.max_abs = std::max(e.max_abs, std::fabs(d));
    e.mean_truth += truth[b];
  }
  e.rms = std::sqrt(e.rms / static_cast<double>(truth.size()));
  e.mean_truth /= static_cast<double>(truth.size());
  return e;
}

// The request's query (the default one when it gives none) and interpolation options.
Status ReadDemoRequest(const DemoRequest& request, std::vector<double>& query,
                       interp::Options& options) {
  query.assign(std::begin(kDemoQuery), std::end(kDemoQuery));
  if (!request.query.empty()) {
    BRDF_ASSIGN_OR_RETURN(std::vector<double> q, ParseNumberList(request.query, "--query"));
    if (q.size() != 3) return InvalidArgument("--query needs three angles: θi,θo,φ");
    query = q;
  }
  options.mirror_phi = request.mirror_phi;
  options.reciprocity = request.reciprocity;
  Result<interp::Coordinates> coordinates = interp::ParseCoordinates(request.coordinates);
  if (!coordinates.ok()) return coordinates.status().WithContext("--coordinates");
  options.coordinates = *coordinates;
  Result<interp::Trend> trend = interp::ParseTrend(request.trend);
  if (!trend.ok()) return trend.status().WithContext("--trend");
  options.trend = *trend;
  if (!request.scale.empty()) {
    BRDF_ASSIGN_OR_RETURN(std::vector<double> scale, ParseNumberList(request.scale, "--scale"));
    options.axis_scale = scale;
  }
  return Status::Ok();
}

void PrintVertices(const interp::Interpolation& answer, const std::vector<double>& query,
                   const interp::Options& options, std::ostream& out) {
  out << "Vertices:\n  letter  row    θi        θo        φ         weight\n";
  for (std::size_t k = 0; k < answer.vertices.size(); ++k) {
    const interp::Vertex& v = answer.vertices[k];
    // For the octant method the letter is the octant the vertex won (relative to the query; in
    // half/difference angles the octants are of (θh, θd, φd), not of the columns shown).
    std::string letter = "-";
    if (answer.method == interp::Method::kOctant &&
        options.coordinates == interp::Coordinates::kIncidence) {
      letter =
          std::string(1, interp::OctantLetter(interp::OrthantOf(v.coords.data(), query.data(), 3)));
    }
    char line[160];
    std::snprintf(line, sizeof line, "  %-6s  %-5zu  %-8.3f  %-8.3f  %-8.3f  %.6f\n",
                  letter.c_str(), v.index, v.coords[0], v.coords[1], v.coords[2], v.weight);
    out << line;
  }
}

// The interpolated spectrum s: its range and mean, and beside the truth every 40 nm.
void PrintSpectrum(const std::vector<double>& s, const std::vector<double>& truth,
                   const WavelengthGrid& wavelengths, std::ostream& out) {
  std::size_t lo = 0, hi = 0;
  double mean = 0;
  for (std::size_t b = 0; b < s.size(); ++b) {
    if (s[b] < s[lo]) lo = b;
    if (s[b] > s[hi]) hi = b;
    mean += s[b];
  }
  mean /= static_cast<double>(s.size());
  out << Format("Spectrum (sr⁻¹): min %.5f at %g nm, max %.5f at %g nm, mean %.5f\n", s[lo],
                wavelengths.at(lo), s[hi], wavelengths.at(hi), mean);
  out << "  nm     interpolated  truth\n";
  for (double nm : {380.0, 420.0, 460.0, 500.0, 540.0, 580.0, 620.0, 660.0, 700.0, 740.0, 780.0}) {
    const auto b =
        static_cast<std::size_t>(std::lround((nm - wavelengths.start_nm) / wavelengths.step_nm));
    if (b >= s.size()) continue;
    out << Format("  %-5g  %-12.5f  %.5f\n", wavelengths.at(b), s[b], truth[b]);
  }
}

// The answer's error against the truth, and for scale the nearest sample's.
void PrintErrors(const std::vector<double>& s, const std::vector<double>& truth,
                 const std::shared_ptr<interp::SampleSet>& samples, const interp::Options& options,
                 const std::vector<double>& query, std::ostream& out) {
  const Error e = Compare(s, truth);
  out << Format(
      "Error against the analytic truth: RMS %.3g sr⁻¹, max |Δ| %.3g sr⁻¹ (RMS %.2f %% of the "
      "mean)\n",
      e.rms, e.max_abs, 100 * e.rms / e.mean_truth);
  auto nearest = MakeNamedInterpolator("nearest", samples, options);
  if (!nearest.ok()) return;
  const interp::Interpolation n = (*nearest)->Evaluate(query);
  if (n.status != interp::InterpStatus::kOk) return;
  const Error ne = Compare(n.spectrum, truth);
  out << Format("For scale, the nearest sample (row %g) alone: RMS %.3g sr⁻¹, max |Δ| %.3g sr⁻¹\n",
                static_cast<double>(n.vertices[0].index), ne.rms, ne.max_abs);
}

}  // namespace

int RunDemo(const DemoRequest& request, std::ostream& out, std::ostream& err) {
  auto fail = [&err](const Status& s) {
    err << "brdf-interp demo: " << s.message() << "\n";
    return ExitCodeFor(s);
  };
  std::vector<double> query;
  interp::Options options;
  if (Status read = ReadDemoRequest(request, query, options); !read.ok()) return fail(read);

  Result<SyntheticPoints> grid = PaperGridPoints();
  if (!grid.ok()) return fail(grid.status());
  const WavelengthGrid wavelengths = WavelengthGrid::Pr650();
  const auto samples = SyntheticSamples(*grid, wavelengths);
  auto interpolator = MakeNamedInterpolator(request.method, samples, options);
  if (!interpolator.ok()) return fail(interpolator.status());

  out << "Paper's rig grid (sample-rotation method, geometry.md): " << grid->poses << " poses, "
      << samples->size() << " distinct (θi, θo, φ) points\n";
  out << "Synthetic sample: AnalyticBrdf::PaintLike() (diffuse paint + glossy lobe), "
      << wavelengths.count << " bands " << wavelengths.start_nm << "–" << wavelengths.last_nm()
      << " nm\n";
  out << Format("Query (θi, θo, φ) = (%g, %g, %g)°, method ", query[0], query[1], query[2])
      << request.method << (options.mirror_phi ? ", mirror φ" : "")
      << (options.reciprocity ? ", reciprocity" : "")
      << (options.coordinates == interp::Coordinates::kHalfDifference
              ? ", in half/difference angles (θh, θd, φd)"
              : "")
      << "\n";

  const interp::Interpolation answer = (*interpolator)->Evaluate(query);
  out << "Status: " << interp::InterpStatusName(answer.status);
  if (!answer.detail.empty()) out << " (" << answer.detail << ")";
  out << "\n";
  if (answer.status != interp::InterpStatus::kOk) {
    out << "No spectrum: the method cannot answer this query (see the status).\n";
    return kExitOk;
  }
  PrintVertices(answer, query, options, out);
  const AnalyticBrdf brdf = SyntheticBrdf(3);
  const std::vector<double> truth = brdf.EvaluateSpectrum(PointDirections(query), wavelengths);
  PrintSpectrum(answer.spectrum, truth, wavelengths, out);
  PrintErrors(answer.spectrum, truth, samples, options, query, out);
  return kExitOk;
}

}  // namespace brdf::interp_tool
