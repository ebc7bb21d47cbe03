#include "core/export/rgl/writer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <utility>

#include "core/export/rgl/warp.h"

namespace brdf::exports {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;
constexpr int kPowerIterations = 40;
constexpr std::size_t kQuadrature = 4096;  // midpoints along u_θ for σ and the normalisation
constexpr double kNdfFloor = 1e-3;         // D never below this fraction of its peak

// Per-node outcome, counted after the parallel run.
enum class Node : std::uint8_t { kInterpolated, kFallback, kBelow, kUnfilled };

double Interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const auto it = std::upper_bound(x.begin(), x.end(), at);
  const std::size_t k = static_cast<std::size_t>(it - x.begin()) - 1;
  const double t = (at - x[k]) / (x[k + 1] - x[k]);
  return y[k] + t * (y[k + 1] - y[k]);
}

// ∫₀^2π max(0, cos θ cos θm + sin θ sin θm cos φ) dφ.
double ClampedCosineRing(double theta, double theta_m) {
  const double a = std::cos(theta) * std::cos(theta_m), b = std::sin(theta) * std::sin(theta_m);
  if (a >= b) return 2 * kPi * a;
  if (a <= -b) return 0;
  const double phi0 = std::acos(-a / b);
  return 2 * (a * phi0 + b * std::sin(phi0));
}

// D as the readers see it: linear in u_θ between the ndf nodes.
double NdfAt(const std::vector<double>& nodes, double u) {
  const double p = std::clamp(u, 0.0, 1.0) * static_cast<double>(nodes.size() - 1);
  const std::size_t k = std::min(static_cast<std::size_t>(p), nodes.size() - 2);
  const double t = p - static_cast<double>(k);
  return nodes[k] * (1 - t) + nodes[k + 1] * t;
}

struct Quadrature {
  std::vector<double> theta_m, weight, d;  // θm, sin θm dθm (per unit φ) at the midpoints
};

Quadrature MakeQuadrature(const std::vector<double>& ndf) {
  Quadrature q;
  const double du = 1.0 / kQuadrature;
  for (std::size_t i = 0; i < kQuadrature; ++i) {
    const double u = (static_cast<double>(i) + 0.5) * du;
    const double tm = u * u * kPi / 2;
    q.theta_m.push_back(tm);
    q.weight.push_back(std::sin(tm) * kPi * u * du);
    q.d.push_back(NdfAt(ndf, u));
  }
  return q;
}

// σ(θ) = ∫ D(ωm) max(0, ωm·ω) dωm for the isotropic D on `q`.
double Sigma(const Quadrature& q, double theta) {
  double s = 0;
  for (std::size_t i = 0; i < q.theta_m.size(); ++i) {
    s += q.d[i] * q.weight[i] * ClampedCosineRing(theta, q.theta_m[i]);
  }
  return s;
}

void Normalise(std::vector<double>& ndf) {
  const Quadrature q = MakeQuadrature(ndf);
  double total = 0;
  for (std::size_t i = 0; i < q.theta_m.size(); ++i) {
    total += q.d[i] * std::cos(q.theta_m[i]) * 2 * kPi * q.weight[i];
  }
  for (double& v : ndf) v /= total;
}

// Dupuy et al. 2015: D(θ) ∝ f(θ, θ) · cos θ · σ[D](θ), by power iteration from a uniform D.
std::vector<double> PowerIteration(const RetroProfile& retro, std::size_t res) {
  std::vector<double> theta(res), f(res);
  for (std::size_t k = 0; k < res; ++k) {
    const double u = static_cast<double>(k) / static_cast<double>(res - 1);
    theta[k] = u * u * kPi / 2;
    f[k] = std::max(0.0, Interpolate(retro.theta_deg, retro.value, theta[k] / kDeg));
  }
  std::vector<double> ndf(res, 1 / kPi);
  for (int it = 0; it < kPowerIterations; ++it) {
    const Quadrature q = MakeQuadrature(ndf);
    std::vector<double> next(res);
    for (std::size_t k = 0; k < res; ++k) {
      next[k] = f[k] * std::cos(theta[k]) * Sigma(q, theta[k]);
    }
    const double peak = *std::max_element(next.begin(), next.end());
    if (!(peak > 0)) return std::vector<double>(res, 1 / kPi);
    for (double& v : next) v = std::max(v, kNdfFloor * peak);
    Normalise(next);
    ndf = std::move(next);
  }
  return ndf;
}

struct Vec3 {
  double x, y, z;
};
double Dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

std::vector<float> ToFloat(const std::vector<double>& v) {
  return {v.begin(), v.end()};
}

RglField FloatField(std::string name, std::vector<std::uint64_t> shape, std::vector<float> v) {
  RglField f;
  f.name = std::move(name);
  f.shape = std::move(shape);
  f.f32 = std::move(v);
  return f;
}

void AppendLe(std::string& out, std::uint64_t v, int bytes) {
  for (int b = 0; b < bytes; ++b) out += static_cast<char>((v >> (8 * b)) & 0xff);
}

Status CheckRglInputs(const WavelengthGrid& bands, const RetroProfile& retro, const RglOptions& o) {
  if (!bands.valid()) return InvalidArgument("RGL export: the wavelength grid is not valid");
  if (o.theta_i_count < 2 || o.sample_res < 2 || o.ndf_res < 2 || o.vndf_res < 2) {
    return InvalidArgument(
        "RGL export: theta_i_count, sample_res, ndf_res and vndf_res must be at least 2");
  }
  if (!(o.theta_i_max_deg > 0 && o.theta_i_max_deg < 90)) {
    return InvalidArgument("RGL export: theta_i_max_deg must be in (0, 90), got " +
                           std::to_string(o.theta_i_max_deg));
  }
  if (retro.theta_deg.size() < 2 || retro.theta_deg.size() != retro.value.size() ||
      !std::is_sorted(retro.theta_deg.begin(), retro.theta_deg.end())) {
    return InvalidArgument(
        "RGL export: the retro-reflection profile needs at least 2 increasing θ with a value "
        "each");
  }
  if (o.rgb && !(o.rgb->grid() == bands)) {
    return InvalidArgument(
        "RGL export: the RGB weights were made for another wavelength grid than the session's");
  }
  return Status::Ok();
}

// The microfacet distribution D and its tables with σ's (two identical φ rows: isotropic).
struct MicrofacetTables {
  std::vector<double> ndf;
  std::vector<float> ndf_table, sigma_table;
};

MicrofacetTables MakeMicrofacetTables(const RetroProfile& retro, std::size_t ndf_res) {
  MicrofacetTables t;
  t.ndf = PowerIteration(retro, ndf_res);
  const Quadrature q = MakeQuadrature(t.ndf);
  std::vector<double> sigma(ndf_res);
  for (std::size_t k = 0; k < ndf_res; ++k) {
    const double u = static_cast<double>(k) / static_cast<double>(ndf_res - 1);
    sigma[k] = Sigma(q, u * u * kPi / 2);
  }
  t.ndf_table = ToFloat(t.ndf);
  t.sigma_table = ToFloat(sigma);
  t.ndf_table.insert(t.ndf_table.end(), t.ndf_table.begin(), t.ndf_table.end());
  t.sigma_table.insert(t.sigma_table.end(), t.sigma_table.begin(), t.sigma_table.end());
  return t;
}

// θi of the slices, radians: 0 to theta_i_max_deg evenly.
std::vector<float> ThetaIGrid(const RglOptions& o) {
  const std::size_t nt = o.theta_i_count;
  std::vector<float> theta_i(nt);
  for (std::size_t j = 0; j < nt; ++j) {
    theta_i[j] = static_cast<float>(o.theta_i_max_deg * kDeg * static_cast<double>(j) /
                                    static_cast<double>(nt - 1));
  }
  return theta_i;
}

// The visible-normal distribution per θi, as a density over (u_θ, u_φ) (with the Jacobian
// 2π² u_θ sin θm of that parameterisation; the warp normalises each slice).
std::vector<float> VisibleNormals(const std::vector<double>& ndf, const std::vector<float>& theta_i,
                                  std::size_t nv) {
  const std::size_t nt = theta_i.size();
  std::vector<float> vndf(nt * nv * nv);
  for (std::size_t j = 0; j < nt; ++j) {
    const Vec3 wi{std::sin(theta_i[j]), 0, std::cos(theta_i[j])};
    for (std::size_t y = 0; y < nv; ++y) {
      for (std::size_t x = 0; x < nv; ++x) {
        const double ux = static_cast<double>(x) / static_cast<double>(nv - 1);
        const double uy = static_cast<double>(y) / static_cast<double>(nv - 1);
        const double tm = ux * ux * kPi / 2, pm = (2 * uy - 1) * kPi;
        const Vec3 m{std::sin(tm) * std::cos(pm), std::sin(tm) * std::sin(pm), std::cos(tm)};
        vndf[(j * nv + y) * nv + x] = static_cast<float>(
            NdfAt(ndf, ux) * std::max(0.0, Dot(wi, m)) * 2 * kPi * kPi * ux * std::sin(tm));
      }
    }
  }
  return vndf;
}

struct SliceWarps {
  Warp2D ndf, sigma, vndf;
};

// The stored values, filled slice (θi) by slice; the slices are disjoint, so the parallel
// workers share it.
struct RglSlices {
  RglSlices(std::size_t nt, std::size_t side, std::size_t bands, bool as_rgb)
      : nb(bands),
        n(side),
        nn(side * side),
        rgb(as_rgb),
        values(nt * (as_rgb ? 3 : bands) * nn, 0.0f),
        luminance(nt * nn, 0.0f),
        outcome(nt * nn, Node::kBelow),
        why(nt * nn, interp::InterpStatus::kOk),
        clamped(nt * nn, 0) {}

  std::size_t nb, n, nn;  // bands; nodes per side and per slice
  bool rgb;
  std::vector<float> values, luminance;
  std::vector<Node> outcome;
  std::vector<interp::InterpStatus> why;
  std::vector<std::uint8_t> clamped;
};

// The nodes of one slice above the horizon: their directions (θi, θo, φ in degrees, three per
// node) and the factor that turns the BRDF into the stored value.
struct SliceNodes {
  std::vector<std::size_t> nodes;
  std::vector<double> directions, scale;
};

SliceNodes WarpSliceNodes(float theta_i, const SliceWarps& warps, std::size_t n) {
  const float param[2] = {0.0f, theta_i};
  const Vec3 wi{std::sin(theta_i), 0, std::cos(theta_i)};
  const float sig =
      warps.sigma.Eval(static_cast<float>(std::sqrt(theta_i * 2 / kPi)), 0.5f, nullptr);
  SliceNodes out;
  for (std::size_t node = 0; node < n * n; ++node) {
    const std::size_t a = node % n, b = node / n;
    const WarpPoint um =
        warps.vndf.Sample(static_cast<float>(a) / static_cast<float>(n - 1),
                          static_cast<float>(b) / static_cast<float>(n - 1), param);
    const double tm = static_cast<double>(um.x) * um.x * kPi / 2;
    const double pm = (2 * static_cast<double>(um.y) - 1) * kPi;
    const Vec3 m{std::sin(tm) * std::cos(pm), std::sin(tm) * std::sin(pm), std::cos(tm)};
    const double c = Dot(wi, m);
    const Vec3 wo{2 * c * m.x - wi.x, 2 * c * m.y - wi.y, 2 * c * m.z - wi.z};
    if (c <= 0 || wo.z <= 1e-6) continue;  // below the horizon: 0
    const double to = std::acos(std::clamp(wo.z, -1.0, 1.0)) / kDeg;
    const double ti = theta_i / kDeg;
    double phi = std::abs(std::atan2(wo.y, wo.x)) / kDeg;
    if (ti < 1e-6 || to < 1e-6) phi = 0;
    out.nodes.push_back(node);
    out.directions.insert(out.directions.end(), {ti, std::min(to, 90.0), std::min(phi, 180.0)});
    const float d = warps.ndf.Eval(um.x, um.y, nullptr);
    out.scale.push_back(wo.z * 4 * static_cast<double>(sig) / static_cast<double>(d));
  }
  return out;
}

// Node `node` of slice j: spectrum s times `scale`, stored as RGB (negative channels clamped
// to 0) or as spectra. Returns its luminance.
double StoreNode(std::size_t j, std::size_t node, std::span<const double> s, double scale,
                 const std::optional<SpectralRgbWeights>& rgb, RglSlices& out) {
  const std::size_t nn = out.nn;
  double lum = 0;
  if (rgb) {
    const Rgb c3 = rgb->Apply(s);
    const double ch[3] = {c3.r, c3.g, c3.b};
    for (std::size_t c = 0; c < 3; ++c) {
      double v = ch[c] * scale;
      if (!(v >= 0)) {
        v = 0;
        out.clamped[j * nn + node] = 1;
      }
      out.values[((j * 3) + c) * nn + node] = static_cast<float>(v);
    }
    lum = (0.2126 * ch[0] + 0.7152 * ch[1] + 0.0722 * ch[2]) * scale;
  } else {
    const std::size_t nb = out.nb;
    for (std::size_t c = 0; c < nb; ++c) {
      out.values[(j * nb + c) * nn + node] = static_cast<float>(s[c] * scale);
      lum += s[c] * scale;
    }
    lum /= static_cast<double>(nb);
  }
  return lum;
}

// Slice j: its nodes' spectra from `source` (else `fallback`), stored; then its luminance
// floored, since sampling must reach every node with a value: a small floor keeps the warp
// defined.
void FillSlice(std::size_t j, float theta_i, const SliceWarps& warps, const SpectrumSource& source,
               const SpectrumSource& fallback, const std::optional<SpectralRgbWeights>& rgb,
               RglSlices& out) {
  const std::size_t nb = out.nb, nn = out.nn;
  const SliceNodes slice = WarpSliceNodes(theta_i, warps, out.n);
  std::vector<interp::InterpStatus> st(slice.nodes.size());
  std::vector<double> spectra(slice.nodes.size() * nb);
  source.Spectra(slice.directions, st, spectra);
  for (std::size_t k = 0; k < slice.nodes.size(); ++k) {
    const std::size_t cell = j * nn + slice.nodes[k];
    std::span<double> s(spectra.data() + k * nb, nb);
    if (st[k] == interp::InterpStatus::kOk) {
      out.outcome[cell] = Node::kInterpolated;
    } else {
      const IsoDirection at{slice.directions[3 * k], slice.directions[3 * k + 1],
                            slice.directions[3 * k + 2]};
      out.why[cell] = st[k];
      if (fallback(at, s) == interp::InterpStatus::kOk) {
        out.outcome[cell] = Node::kFallback;
      } else {
        out.outcome[cell] = Node::kUnfilled;
        continue;
      }
    }
    const double lum = StoreNode(j, slice.nodes[k], s, slice.scale[k], rgb, out);
    out.luminance[cell] = static_cast<float>(std::max(0.0, lum));
  }
  float peak = 0;
  for (std::size_t node = 0; node < nn; ++node) {
    peak = std::max(peak, out.luminance[j * nn + node]);
  }
  const float floor = peak > 0 ? peak * 1e-4f : 1.0f;
  for (std::size_t node = 0; node < nn; ++node) {
    out.luminance[j * nn + node] = std::max(out.luminance[j * nn + node], floor);
  }
}

RglReport CountNodes(const RglSlices& slices, const std::string& retro_origin) {
  RglReport report;
  report.cells = slices.outcome.size();
  report.retro_origin = retro_origin;
  for (std::size_t cell = 0; cell < slices.outcome.size(); ++cell) {
    switch (slices.outcome[cell]) {
      case Node::kInterpolated:
        ++report.interpolated;
        break;
      case Node::kFallback:
        ++report.fallback;
        break;
      case Node::kBelow:
        ++report.below_horizon;
        break;
      case Node::kUnfilled:
        ++report.unfilled[slices.why[cell]];
        break;
    }
    report.clamped += slices.clamped[cell];
  }
  return report;
}

// The description and jacobian fields, which the file starts with.
void AddDescription(const std::string& description, std::vector<RglField>& fields) {
  RglField desc;
  desc.name = "description";
  desc.is_u8 = true;
  desc.u8.assign(description.begin(), description.end());
  desc.shape = {desc.u8.size()};
  RglField jac;
  jac.name = "jacobian";
  jac.is_u8 = true;
  jac.u8 = {1};
  jac.shape = {1};
  fields.push_back(std::move(desc));
  fields.push_back(std::move(jac));
}

// The luminance field, then the rgb field or the wavelengths and spectra fields.
void AddValues(const WavelengthGrid& bands, RglSlices&& slices, std::vector<RglField>& fields) {
  const std::size_t nt = slices.luminance.size() / slices.nn, n = slices.n, nb = bands.count;
  fields.push_back(FloatField("luminance", {1, nt, n, n}, std::move(slices.luminance)));
  if (slices.rgb) {
    fields.push_back(FloatField("rgb", {1, nt, 3, n, n}, std::move(slices.values)));
  } else {
    std::vector<float> wl(nb);
    for (std::size_t c = 0; c < nb; ++c) wl[c] = static_cast<float>(bands.at(c));
    fields.push_back(FloatField("wavelengths", {nb}, std::move(wl)));
    fields.push_back(FloatField("spectra", {1, nt, nb, n, n}, std::move(slices.values)));
  }
}

}  // namespace

std::size_t RglReport::unfilled_total() const {
  std::size_t n = 0;
  for (const auto& [status, count] : unfilled) n += count;
  return n;
}

std::string RglReport::Summary() const {
  std::string s = std::to_string(cells) + " nodes: " + std::to_string(interpolated) +
                  " interpolated, " + std::to_string(fallback) + " from the fallback, " +
                  std::to_string(below_horizon) + " below the horizon, " +
                  std::to_string(unfilled_total()) + " unfilled (0)";
  if (clamped > 0) s += ", " + std::to_string(clamped) + " clamped to the sRGB gamut";
  s += "; microfacet distribution from " + retro_origin;
  return s;
}

Result<RetroProfile> RetroReflectionFromSamples(const DerivedSamples& derived,
                                                double tolerance_deg) {
  std::map<long long, std::pair<double, std::size_t>> by_theta;  // key: θ in 1/100 °
  std::map<long long, double> theta_sum;
  for (const DerivedSample& s : derived.samples) {
    if (std::abs(s.iso.theta_i - s.iso.theta_o) > tolerance_deg) continue;
    if (s.iso.theta_i > tolerance_deg && s.iso.phi > tolerance_deg) continue;
    double mean = 0;
    for (double v : s.values) mean += v;
    mean /= static_cast<double>(std::max<std::size_t>(1, s.values.size()));
    if (!std::isfinite(mean)) continue;
    const long long key = std::llround(s.iso.theta_i * 100);
    by_theta[key].first += mean;
    by_theta[key].second += 1;
    theta_sum[key] += s.iso.theta_i;
  }
  if (by_theta.size() < 3) {
    return FailedPrecondition("the session has retro-reflection readings (δ = 0) at " +
                              std::to_string(by_theta.size()) +
                              " distinct θ; at least 3 are needed for the power iteration");
  }
  RetroProfile p;
  std::size_t readings = 0;
  for (const auto& [key, acc] : by_theta) {
    p.theta_deg.push_back(theta_sum[key] / static_cast<double>(acc.second));
    p.value.push_back(acc.first / static_cast<double>(acc.second));
    readings += acc.second;
  }
  p.origin = std::to_string(readings) + " retro-reflection readings at " +
             std::to_string(by_theta.size()) + " θ (power iteration)";
  return p;
}

Result<RglExport> BuildRgl(const SpectrumSource& source, const SpectrumSource& fallback,
                           const WavelengthGrid& bands, const RetroProfile& retro,
                           const RglOptions& o, const RunControl& control, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(CheckRglInputs(bands, retro, o));
  const std::size_t nt = o.theta_i_count;
  MicrofacetTables microfacets = MakeMicrofacetTables(retro, o.ndf_res);
  const std::vector<float> theta_i = ThetaIGrid(o);
  const std::vector<float> phi_i = {0.0f};
  std::vector<float> vndf = VisibleNormals(microfacets.ndf, theta_i, o.vndf_res);
  const SliceWarps warps{Warp2D(o.ndf_res, 2, microfacets.ndf_table.data(), {}, false, false),
                         Warp2D(o.ndf_res, 2, microfacets.sigma_table.data(), {}, false, false),
                         Warp2D(o.vndf_res, o.vndf_res, vndf.data(), {phi_i, theta_i}, true, true)};

  // The stored values at the warped nodes, slice by slice.
  RglSlices slices(nt, o.sample_res, bands.count, o.rgb.has_value());
  ProgressReporter progress(control.progress, nt);
  BRDF_RETURN_IF_ERROR(ParallelForChunks(nt, 1, ResolveThreads(control.threads), ctx, &progress, 0,
                                         "RGL table", [&](std::size_t begin, std::size_t end) {
                                           for (std::size_t j = begin; j < end; ++j) {
                                             FillSlice(j, theta_i[j], warps, source, fallback,
                                                       o.rgb, slices);
                                           }
                                         }));

  RglExport result;
  result.report = CountNodes(slices, retro.origin);
  AddDescription(o.description, result.fields);
  result.fields.push_back(FloatField("theta_i", {nt}, theta_i));
  result.fields.push_back(FloatField("phi_i", {1}, phi_i));
  result.fields.push_back(FloatField("ndf", {2, o.ndf_res}, std::move(microfacets.ndf_table)));
  result.fields.push_back(FloatField("sigma", {2, o.ndf_res}, std::move(microfacets.sigma_table)));
  result.fields.push_back(FloatField("vndf", {1, nt, o.vndf_res, o.vndf_res}, std::move(vndf)));
  AddValues(bands, std::move(slices), result.fields);
  progress.Finish();
  return result;
}

Status WriteRgl(const std::vector<RglField>& fields, std::ostream& out) {
  std::string head("tensor_file", 11);
  head += '\0';
  head += static_cast<char>(1);
  head += static_cast<char>(0);
  AppendLe(head, fields.size(), 4);
  std::size_t table = head.size();
  for (const RglField& f : fields) table += 2 + f.name.size() + 2 + 1 + 8 + 8 * f.shape.size();
  std::vector<std::uint64_t> offsets;
  std::uint64_t at = table;
  for (const RglField& f : fields) {
    at = (at + 7) / 8 * 8;
    offsets.push_back(at);
    at += f.is_u8 ? f.u8.size() : 4 * f.f32.size();
  }
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const RglField& f = fields[i];
    AppendLe(head, f.name.size(), 2);
    head += f.name;
    AppendLe(head, f.shape.size(), 2);
    head += static_cast<char>(f.is_u8 ? 1 : 10);  // uint8, float32
    AppendLe(head, offsets[i], 8);
    for (std::uint64_t d : f.shape) AppendLe(head, d, 8);
  }
  out.write(head.data(), static_cast<std::streamsize>(head.size()));
  std::uint64_t written = head.size();
  std::string buffer;
  for (std::size_t i = 0; i < fields.size() && out; ++i) {
    const RglField& f = fields[i];
    buffer.assign(offsets[i] - written, '\0');
    if (f.is_u8) {
      buffer.append(f.u8.begin(), f.u8.end());
    } else {
      for (float v : f.f32) AppendLe(buffer, std::bit_cast<std::uint32_t>(v), 4);
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    written += buffer.size();
  }
  out.flush();
  if (!out) return IoError("writing the RGL .bsdf failed: is the disk full or read-only?");
  return Status::Ok();
}

}  // namespace brdf::exports
