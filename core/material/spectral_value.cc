#include "core/material/spectral_value.h"

#include <algorithm>
#include <cmath>

namespace brdf::material {

SpectralValue SpectralValue::Constant(double value) {
  SpectralValue s;
  s.value_ = value;
  return s;
}

SpectralValue SpectralValue::Table(std::vector<std::pair<double, double>> points) {
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (!(points[i].first > points[i - 1].first)) return Constant(0);
  }
  if (points.empty()) return Constant(0);
  if (points.size() == 1) return Constant(points.front().second);
  SpectralValue s;
  s.kind_ = Kind::kTable;
  s.points_ = std::move(points);
  return s;
}

SpectralValue SpectralValue::Bump(double base, double amplitude, double center_nm,
                                  double width_nm) {
  SpectralValue s;
  s.kind_ = Kind::kBump;
  s.value_ = base;
  s.amplitude_ = amplitude;
  s.center_nm_ = center_nm;
  s.width_nm_ = width_nm;
  return s;
}

double SpectralValue::At(double nm) const {
  switch (kind_) {
    case Kind::kConstant:
      return value_;
    case Kind::kBump: {
      // Written as core/analytic_brdf.cc writes the paint's albedo, so that the two agree to the
      // last bit.
      const double u = (nm - center_nm_) / width_nm_;
      return value_ + amplitude_ * std::exp(-u * u);
    }
    case Kind::kTable:
      break;
  }
  if (nm <= points_.front().first) return points_.front().second;
  if (nm >= points_.back().first) return points_.back().second;
  const auto above = std::upper_bound(points_.begin(), points_.end(), nm,
                                      [](double x, const auto& p) { return x < p.first; });
  const auto& [x1, y1] = *above;
  const auto& [x0, y0] = *(above - 1);
  const double t = (nm - x0) / (x1 - x0);
  return y0 + t * (y1 - y0);
}

std::pair<double, double> SpectralValue::Range() const {
  switch (kind_) {
    case Kind::kConstant:
      return {value_, value_};
    case Kind::kBump:
      return {value_ + std::min(amplitude_, 0.0), value_ + std::max(amplitude_, 0.0)};
    case Kind::kTable:
      break;
  }
  const auto [lo, hi] =
      std::minmax_element(points_.begin(), points_.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; });
  return {lo->second, hi->second};
}

}  // namespace brdf::material
