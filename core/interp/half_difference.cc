#include "core/interp/half_difference.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "core/geometry.h"

namespace brdf::interp {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

struct V3 {
  double x, y, z;
};

V3 FromAngles(double theta_deg, double phi_deg) {
  const double t = theta_deg * kDegToRad, p = phi_deg * kDegToRad;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// Rz(a)·v and Ry(b)·v (right-handed, radians).
V3 RotateZ(V3 v, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {v.x * c - v.y * s, v.x * s + v.y * c, v.z};
}
V3 RotateY(V3 v, double b) {
  const double c = std::cos(b), s = std::sin(b);
  return {v.x * c + v.z * s, v.y, v.z * c - v.x * s};
}

double Theta(V3 v) {
  return std::atan2(std::hypot(v.x, v.y), v.z);
}

// The answer of the inner interpolator (over half/difference points) with its vertices turned
// back into (θi, θo, φ) and into indices of the measured samples.
void ToIncidenceVertices(Interpolation& answer, std::size_t measured) {
  for (Vertex& v : answer.vertices) {
    v.index %= measured;
    if (v.coords.size() == 3) {
      const IsoDirection iso = FromHalfDifference(
          FromHalfDifferencePoint(std::array<double, 3>{v.coords[0], v.coords[1], v.coords[2]}));
      v.coords = {iso.theta_i, iso.theta_o, iso.phi};
    }
  }
}

class HalfDifferenceInterpolator final : public Interpolator {
 public:
  // `images_bytes`: the heap of the set of images `inner` was built over.
  HalfDifferenceInterpolator(std::unique_ptr<Interpolator> inner, std::size_t measured,
                             std::size_t images_bytes)
      : inner_(std::move(inner)), measured_(measured), images_bytes_(images_bytes) {}

  Method method() const override { return inner_->method(); }
  int dims() const override { return 3; }
  std::size_t HeapBytes() const override {
    return sizeof(*this) + images_bytes_ + inner_->HeapBytes();
  }

  Interpolation Evaluate(std::span<const double> query) const override {
    if (query.size() != 3) return inner_->Evaluate(query);  // the method's own "wrong size"
    const std::array<double, 3> p = Map(query);
    Interpolation answer = inner_->Evaluate(p);
    ToIncidenceVertices(answer, measured_);
    return answer;
  }

  InterpStatus SpectrumAt(std::span<const double> query,
                          std::span<double> spectrum) const override {
    if (query.size() != 3) return inner_->SpectrumAt(query, spectrum);
    const std::array<double, 3> p = Map(query);
    return inner_->SpectrumAt(p, spectrum);
  }

  void EvaluateEach(std::span<const double> queries, const TakeAnswer& take) const override {
    const std::vector<double> mapped = MapAll(queries);
    inner_->EvaluateEach(mapped, [&](std::size_t i, Interpolation&& answer) {
      ToIncidenceVertices(answer, measured_);
      return take(i, std::move(answer));
    });
  }

  void SpectraAt(std::span<const double> queries, std::span<InterpStatus> statuses,
                 std::span<double> spectra) const override {
    const std::vector<double> mapped = MapAll(queries);
    inner_->SpectraAt(mapped, statuses, spectra);
  }

 private:
  static std::array<double, 3> Map(std::span<const double> q) {
    return HalfDifferencePoint(ToHalfDifference({q[0], q[1], q[2]}));
  }
  static std::vector<double> MapAll(std::span<const double> queries) {
    std::vector<double> mapped(queries.size() - queries.size() % 3);
    for (std::size_t i = 0; i + 3 <= queries.size(); i += 3) {
      const std::array<double, 3> p = Map(queries.subspan(i, 3));
      std::copy(p.begin(), p.end(), mapped.begin() + static_cast<std::ptrdiff_t>(i));
    }
    return mapped;
  }

  std::unique_ptr<Interpolator> inner_;
  std::size_t measured_;
  std::size_t images_bytes_;
};

}  // namespace

HalfDiffAngles ToHalfDifference(const IsoDirection& iso) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(iso.theta_i) || !std::isfinite(iso.theta_o) || !std::isfinite(iso.phi)) {
    return {kNaN, kNaN, kNaN};
  }
  const V3 wi = FromAngles(iso.theta_i, 0.0);
  const V3 wo = FromAngles(iso.theta_o, iso.phi);
  const V3 sum{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double len = std::sqrt(sum.x * sum.x + sum.y * sum.y + sum.z * sum.z);
  if (len < 1e-12) return {90.0, 90.0, 90.0};  // grazing and opposite: no half vector
  const V3 h{sum.x / len, sum.y / len, sum.z / len};
  const double theta_h = Theta(h);
  // At the pole the azimuth of h is rounding noise: take 0 (and φd = 0 below, as documented).
  const bool pole = theta_h * kRadToDeg < kNormalThetaEpsilonDeg;
  const double phi_h = pole ? 0.0 : std::atan2(h.y, h.x);
  const V3 d = RotateY(RotateZ(wi, -phi_h), -theta_h);
  HalfDiffAngles out;
  out.theta_h = theta_h * kRadToDeg;
  out.theta_d = Theta(d) * kRadToDeg;
  out.phi_d = pole || out.theta_d < kNormalThetaEpsilonDeg
                  ? 0.0
                  : std::fabs(std::atan2(d.y, d.x)) * kRadToDeg;
  return out;
}

std::array<double, 3> HalfDifferencePoint(const HalfDiffAngles& hd) {
  const double phi = hd.phi_d * kDegToRad;
  return {hd.theta_h * std::cos(phi), hd.theta_h * std::sin(phi), hd.theta_d};
}

HalfDiffAngles FromHalfDifferencePoint(const std::array<double, 3>& p) {
  return {std::hypot(p[0], p[1]), p[2], std::atan2(p[1], p[0]) * kRadToDeg};
}

IsoDirection FromHalfDifference(const HalfDiffAngles& hd) {
  const V3 d = FromAngles(hd.theta_d, hd.phi_d);
  const V3 wi = RotateY(d, hd.theta_h * kDegToRad);
  const V3 h = FromAngles(hd.theta_h, 0.0);
  const double twice_cos = 2 * (h.x * wi.x + h.y * wi.y + h.z * wi.z);
  const V3 wo{twice_cos * h.x - wi.x, twice_cos * h.y - wi.y, twice_cos * h.z - wi.z};
  Directions dirs;
  dirs.theta_i = Theta(wi) * kRadToDeg;
  dirs.phi_i = std::atan2(wi.y, wi.x) * kRadToDeg;
  dirs.theta_o = Theta(wo) * kRadToDeg;
  dirs.phi_o = std::atan2(wo.y, wo.x) * kRadToDeg;
  return ToIsotropic(dirs);
}

Result<std::unique_ptr<Interpolator>> MakeHalfDifferenceInterpolator(
    Method method, std::shared_ptr<const SampleSet> samples, const Options& options) {
  if (!samples || samples->size() == 0) {
    return InvalidArgument("no samples to interpolate between");
  }
  if (samples->dims() != 3) {
    return InvalidArgument(
        "coordinates: half_difference needs isotropic (θi, θo, φ) data; these samples have " +
        std::to_string(samples->dims()) + " coordinates (use incidence coordinates)");
  }
  const std::size_t n = samples->size();
  std::vector<std::array<double, 3>> points;
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = samples->coords(i);
    points.push_back(HalfDifferencePoint(ToHalfDifference({c[0], c[1], c[2]})));
  }
  // The images, one block per kind, in the order of the header: (x, −y, θd) and (−x, y, −θd)
  // always, (−x, y, θd) with reciprocity.
  std::vector<std::array<double, 3>> images = {{1, -1, 1}, {-1, 1, -1}};
  if (options.reciprocity) images.push_back({-1, 1, 1});
  auto set = std::make_shared<SampleSet>(3, samples->bands());
  auto add = [&](std::size_t i, const std::array<double, 3>& sign) {
    const double coords[3] = {sign[0] * points[i][0], sign[1] * points[i][1],
                              sign[2] * points[i][2]};
    return set->Add(samples->id(i), coords, samples->spectrum(i));
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (Status s = add(i, {1, 1, 1}); !s.ok()) return s;
  }
  for (const std::array<double, 3>& sign : images) {
    for (std::size_t i = 0; i < n; ++i) {
      if (Status s = add(i, sign); !s.ok()) return s;
    }
  }
  Options inner = options;
  inner.coordinates = Coordinates::kIncidence;
  inner.mirror_phi = inner.reciprocity = false;
  if (inner.axis_scale.empty()) {
    inner.axis_scale.assign(kHalfDifferenceScale.begin(), kHalfDifferenceScale.end());
  }
  const std::size_t images_bytes = sizeof(SampleSet) + set->HeapBytes();
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<Interpolator> made,
                        MakeInterpolator(method, std::move(set), inner));
  return std::unique_ptr<Interpolator>(
      new HalfDifferenceInterpolator(std::move(made), n, images_bytes));
}

}  // namespace brdf::interp
