#include "interp_test_data.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/analytic_brdf.h"
#include "core/pose.h"
#include "core/wavelength_grid.h"

namespace brdf::interp::testing {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;
double Deg(double rad) {
  return rad / kRad;
}

// A uniform double in [0, 1) from 53 random bits (the same on every standard library).
double Uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

}  // namespace

std::vector<Point> RigPoseQueries(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Point> out;
  while (out.size() < n) {
    const double a = 70 * u(rng) * kRad, b = (-175 + 355 * u(rng)) * kRad,
                 d = 146.25 * u(rng) * kRad;
    const double ci = std::cos(a) * std::cos(b), co = std::cos(a) * std::cos(b - d);
    const double ti = Deg(std::acos(ci)), to = Deg(std::acos(co));
    if (ti > 89.999 || to > 89.999 || ti < 1e-6 || to < 1e-6) continue;
    const double c = (std::cos(d) - ci * co) / (std::sin(ti * kRad) * std::sin(to * kRad));
    out.push_back({ti, to, Deg(std::acos(std::clamp(c, -1.0, 1.0)))});
  }
  return out;
}

std::vector<Point> PaperGrid(int* poses) {
  std::vector<Point> out;
  int count = 0;
  for (int k = 0; k < 14; ++k) {
    const double delta = 11.25 * k;
    for (int alpha = 0; alpha <= 70; alpha += 10) {
      for (int beta = -175; beta <= 180; beta += 5) {
        const double ca = std::cos(alpha * kRad);
        const double ci = ca * std::cos(beta * kRad);
        const double co = ca * std::cos((beta - delta) * kRad);
        const double ti = Deg(std::acos(std::clamp(ci, -1.0, 1.0)));
        const double to = Deg(std::acos(std::clamp(co, -1.0, 1.0)));
        if (ti > 89.999 || to > 89.999) continue;
        ++count;
        double phi = 0.0;
        if (ti > 1e-7 && to > 1e-7) {
          const double c =
              (std::cos(delta * kRad) - ci * co) / (std::sin(ti * kRad) * std::sin(to * kRad));
          phi = Deg(std::acos(std::clamp(c, -1.0, 1.0)));
        }
        const Point p = {ti, to, phi};
        const bool seen = std::any_of(out.begin(), out.end(), [&](const Point& q) {
          return std::fabs(q[0] - p[0]) < 1e-6 && std::fabs(q[1] - p[1]) < 1e-6 &&
                 std::fabs(q[2] - p[2]) < 1e-6;
        });
        if (!seen) out.push_back(p);
      }
    }
  }
  if (poses != nullptr) *poses = count;
  return out;
}

std::vector<Point> RandomPoints(std::size_t n, const std::vector<double>& lo,
                                const std::vector<double>& hi, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Point> out(n, Point(lo.size()));
  for (auto& p : out) {
    for (std::size_t j = 0; j < lo.size(); ++j) p[j] = lo[j] + (hi[j] - lo[j]) * Uniform(rng);
  }
  return out;
}

std::vector<Point> Lattice(int dims, int size, double step) {
  std::vector<Point> out;
  int total = 1;
  for (int j = 0; j < dims; ++j) total *= size;
  for (int i = 0; i < total; ++i) {
    Point p(static_cast<std::size_t>(dims));
    int rest = i;
    for (int j = dims - 1; j >= 0; --j) {
      p[static_cast<std::size_t>(j)] = step * (rest % size);
      rest /= size;
    }
    out.push_back(p);
  }
  return out;
}

SpectrumFn LinearSpectrum(int dims, int bands) {
  return [dims, bands](const Point& p) {
    std::vector<double> s(static_cast<std::size_t>(bands));
    for (int b = 0; b < bands; ++b) {
      double v = 0.5 + 0.01 * b;
      for (int j = 0; j < dims; ++j)
        v += (0.003 * (j + 1) - 0.0007 * b) * p[static_cast<std::size_t>(j)];
      s[static_cast<std::size_t>(b)] = v;
    }
    return s;
  };
}

SpectrumFn AnalyticSpectrum(int dims) {
  const AnalyticBrdf brdf = dims == 3 ? AnalyticBrdf::PaintLike() : AnalyticBrdf::Brushed();
  return [brdf, dims](const Point& p) {
    Directions d;
    if (dims == 3) {
      d = {p[0], 0.0, p[1], p[2]};
    } else {
      d = {p[0], p[1], p[2], p[3]};
    }
    return brdf.EvaluateSpectrum(d, WavelengthGrid::Pr650());
  };
}

std::shared_ptr<SampleSet> MakeSamples(const std::vector<Point>& points, const SpectrumFn& fn,
                                       std::int64_t first_id) {
  const int dims = static_cast<int>(points.at(0).size());
  const int bands = static_cast<int>(fn(points[0]).size());
  auto set = std::make_shared<SampleSet>(dims, bands);
  std::int64_t id = first_id;
  for (const Point& p : points) {
    const Status s = set->Add(id++, p, fn(p));
    if (!s.ok()) return nullptr;
  }
  return set;
}

}  // namespace brdf::interp::testing
