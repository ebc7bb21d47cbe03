#include "core/adaptive/interpolated_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "core/adaptive/judged_readings.h"
#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

constexpr double kThetaStepDeg = 5;
constexpr double kPhiStepDeg = 10;
constexpr double kBucketDeg = 10;
constexpr int kBuckets[3] = {9, 9, 18};  // θi, θo over [0, 90], φ over [0, 180]

double Rad(double deg) {
  return deg * std::numbers::pi / 180;
}

// Cell centres every `step` within [lo, hi]; the middle when the range is narrower than a step.
std::vector<double> Centres(double lo, double hi, double step) {
  std::vector<double> out;
  for (double x = lo + step / 2; x < hi + 1e-9; x += step) out.push_back(x);
  if (out.empty()) out.push_back((lo + hi) / 2);
  return out;
}

// One evaluation direction: where it is, its share of the region, its cosine weight.
struct EvalPoint {
  std::array<double, 3> x;  // θi, θo, φ (degrees)
  double measure = 0;       // sin θi · sin θo (the lattice's cells are equal in angle)
  double cosine = 0;        // cos θi · cos θo
};

std::vector<EvalPoint> EvaluationDirections(const Region& region) {
  std::vector<EvalPoint> out;
  const std::vector<double> ti =
      Centres(region.theta_i_min_deg, region.theta_i_max_deg, kThetaStepDeg);
  const std::vector<double> to =
      Centres(region.theta_o_min_deg, region.theta_o_max_deg, kThetaStepDeg);
  const std::vector<double> phi = Centres(0, 180, kPhiStepDeg);
  for (double a : ti) {
    for (double b : to) {
      for (double p : phi) {
        out.push_back(
            {{a, b, p}, std::sin(Rad(a)) * std::sin(Rad(b)), std::cos(Rad(a)) * std::cos(Rad(b))});
      }
    }
  }
  return out;
}

double Distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
  return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

int OrthantAbout(const std::array<double, 3>& p, const std::array<double, 3>& e) {
  return (p[0] >= e[0] ? 1 : 0) | (p[1] >= e[1] ? 2 : 0) | (p[2] >= e[2] ? 4 : 0);
}

// What the map keeps of one evaluation direction.
struct Cell {
  bool answered = false;
  double v_measurement = 0;  // (cos · u_m)², absolute
  double v_interpolation = 0;  // (cos · u_int)², absolute; unknown: (cos · kUnknownRelative · F)²
  int vertex_count = 0;
  std::array<std::array<double, 3>, 4> vertex{};  // answered: the simplex's vertices
  double radius = 0;                              // answered: the largest vertex distance
  // Per orthant, the nearest reading's squared distance (+∞: empty; squared, so that a reading
  // at the very point compares equal, not by a rounding of the root).
  std::array<double, 8> nearest2{};
};

// What a reading at p would do to one cell.
struct CellEffect {
  double factor = 1;  // the interpolation variance's new share
  int orthant = 0;    // p's orthant about the cell's direction
  double distance = 0;
  double squared = 0;
  int replaced = -1;  // answered: the vertex p takes the place of
};

// An answered cell: p enters when it is nearer than its orthant's nearest reading; it takes the
// place of the simplex's vertex in that orthant (or of the farthest one) and the cell shrinks.
bool AnsweredEffect(const Cell& cell, const std::array<double, 3>& e, CellEffect* out) {
  int which = -1, farthest = 0;
  double far_distance = -1;
  for (int i = 0; i < cell.vertex_count; ++i) {
    const double di = Distance(cell.vertex[i], e);
    if (di > far_distance) far_distance = di, farthest = i;
    if (OrthantAbout(cell.vertex[i], e) == out->orthant) which = i;
  }
  if (which < 0) which = farthest;
  double after = out->distance;
  for (int i = 0; i < cell.vertex_count; ++i) {
    if (i != which) after = std::max(after, Distance(cell.vertex[i], e));
  }
  if (!(after < cell.radius)) return false;
  out->factor = (after / cell.radius) * (after / cell.radius);
  out->replaced = which;
  return true;
}

// An unknown cell: p helps when it fills one of its E empty orthants, by a share 1/E, more the
// nearer it is (all of it only when it fills the last one at distance 0).
bool UnknownEffect(const Cell& cell, CellEffect* out) {
  if (!(out->distance < kReachDeg)) return false;
  int empty = 0;
  for (double n : cell.nearest2) empty += std::isinf(n) ? 1 : 0;
  const double near = (out->distance / kReachDeg) * (out->distance / kReachDeg);
  if (empty == 0) {  // every orthant holds a reading, yet no simplex encloses the direction
    out->factor = near;
    return true;
  }
  if (!std::isinf(cell.nearest2[out->orthant])) return false;
  out->factor = (empty - 1 + near) / empty;
  return true;
}

bool Effect(const Cell& cell, const std::array<double, 3>& e, const std::array<double, 3>& p,
            CellEffect* out) {
  const double d0 = p[0] - e[0], d1 = p[1] - e[1], d2 = p[2] - e[2];
  const double squared = d0 * d0 + d1 * d1 + d2 * d2;
  const double reach = cell.answered ? std::min(cell.radius, kReachDeg) : kReachDeg;
  if (!(squared < reach * reach)) return false;
  out->orthant = OrthantAbout(p, e);
  if (!(squared < cell.nearest2[out->orthant])) return false;
  out->squared = squared;
  out->distance = std::sqrt(squared);
  return cell.answered ? AnsweredEffect(cell, e, out) : UnknownEffect(cell, out);
}

class InterpolatedMap final : public UncertaintyMap {
 public:
  InterpolatedMap(std::vector<EvalPoint> points, std::vector<Cell> cells, double k,
                  bool with_measurement, double scale_squared)
      : points_(std::move(points)),
        cells_(std::move(cells)),
        k_(k),
        with_measurement_(with_measurement) {
    for (const EvalPoint& p : points_) measure_ += p.measure;
    denominator_ = scale_squared;
    IndexBuckets();
    Sum();
  }

  double Remaining() const override { return RemainingFor(sum_); }

  double PredictedGain(const Directions& candidate) const override {
    double fall = 0;
    Visit(Point(candidate), [&](std::size_t i, const CellEffect& effect) {
      fall += points_[i].measure * cells_[i].v_interpolation * (1 - effect.factor);
    });
    if (!(fall > 0)) return 0;
    return std::max(0.0, RemainingFor(sum_) - RemainingFor(sum_ - fall));
  }

  void Assume(const Directions& chosen) override {
    const std::array<double, 3> p = Point(chosen);
    Visit(p, [&](std::size_t i, const CellEffect& effect) {
      Cell& cell = cells_[i];
      cell.v_interpolation *= effect.factor;
      cell.nearest2[effect.orthant] = effect.squared;
      if (effect.replaced >= 0) {
        cell.vertex[effect.replaced] = p;
        cell.radius *= std::sqrt(effect.factor);
      }
    });
    Sum();
  }

 private:
  static std::array<double, 3> Point(const Directions& d) {
    const IsoDirection iso = ToIsotropic(d);
    return {iso.theta_i, iso.theta_o, iso.phi};
  }

  static int BucketOf(double x, int axis) {
    return std::clamp(static_cast<int>(std::floor(x / kBucketDeg)), 0, kBuckets[axis] - 1);
  }

  void IndexBuckets() {
    buckets_.assign(kBuckets[0] * kBuckets[1] * kBuckets[2], {});
    bucket_reach_.assign(buckets_.size(), 0);
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const auto& x = points_[i].x;
      const int b =
          (BucketOf(x[0], 0) * kBuckets[1] + BucketOf(x[1], 1)) * kBuckets[2] + BucketOf(x[2], 2);
      const double reach = cells_[i].answered ? std::min(cells_[i].radius, kReachDeg) : kReachDeg;
      buckets_[b].push_back(i);
      bucket_reach_[b] = std::max(bucket_reach_[b], reach);
      reach_ = std::max(reach_, reach);
    }
  }

  // The squared distance from p to bucket (b0, b1, b2)'s box (the outermost ones open outwards).
  static double BoxDistanceSquared(const std::array<double, 3>& p, const int (&b)[3]) {
    double sum = 0;
    for (int a = 0; a < 3; ++a) {
      const double lo = b[a] == 0 ? -INFINITY : b[a] * kBucketDeg;
      const double hi = b[a] == kBuckets[a] - 1 ? INFINITY : (b[a] + 1) * kBucketDeg;
      const double gap = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0);
      sum += gap * gap;
    }
    return sum;
  }

  // Calls f(point, effect) for every evaluation direction a reading at p would enter,
  // in the points' order within buckets visited in a fixed order (deterministic).
  template <typename F>
  void Visit(const std::array<double, 3>& p, F&& f) const {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return;
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = BucketOf(p[a] - reach_, a);
      hi[a] = BucketOf(p[a] + reach_, a);
    }
    for (int b0 = lo[0]; b0 <= hi[0]; ++b0) {
      for (int b1 = lo[1]; b1 <= hi[1]; ++b1) {
        for (int b2 = lo[2]; b2 <= hi[2]; ++b2) {
          const int b = (b0 * kBuckets[1] + b1) * kBuckets[2] + b2;
          const double reach = bucket_reach_[b];
          if (!(BoxDistanceSquared(p, {b0, b1, b2}) < reach * reach)) continue;
          for (std::size_t i : buckets_[b]) {
            CellEffect effect;
            if (Effect(cells_[i], points_[i].x, p, &effect)) f(i, effect);
          }
        }
      }
    }
  }

  void Sum() {
    sum_ = 0;
    for (std::size_t i = 0; i < cells_.size(); ++i) {
      const double v =
          cells_[i].v_interpolation + (with_measurement_ ? cells_[i].v_measurement : 0.0);
      sum_ += points_[i].measure * v;
    }
  }

  double RemainingFor(double sum) const {
    if (!(measure_ > 0) || !(denominator_ > 0)) return 0;
    return k_ * std::sqrt(std::max(0.0, sum) / measure_ / denominator_);
  }

  std::vector<EvalPoint> points_;
  std::vector<Cell> cells_;
  double k_;
  bool with_measurement_;
  double measure_ = 0;
  double denominator_ = 1;  // Y²: the mean square cosine-weighted BRDF
  double sum_ = 0;
  double reach_ = 0;  // the largest radius when built (radii only shrink)
  std::vector<std::vector<std::size_t>> buckets_;
  std::vector<double> bucket_reach_;  // per bucket, the largest reach of its cells when built
};

// The cells from the judged interpolant's answers; unknown cells get `unknown_v` per unit cos².
std::vector<Cell> AnswerCells(const std::vector<EvalPoint>& points, const JudgedReadings& judged,
                              double* mean_square, double* mean_square_cosine) {
  std::vector<Cell> cells(points.size());
  double m_all = 0, m_answered = 0, y2 = 0, cy2 = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    m_all += points[i].measure;
    cells[i].nearest2 = judged.OrthantNearest2(points[i].x);
    const std::optional<JudgedAnswer> a = judged.Answer(points[i].x);
    if (!a.has_value()) continue;
    Cell& cell = cells[i];
    const double c2 = points[i].cosine * points[i].cosine;
    cell.answered = true;
    cell.v_measurement = c2 * a->u_measurement * a->u_measurement;
    cell.v_interpolation = c2 * a->u_interpolation * a->u_interpolation;
    cell.vertex_count = std::min<int>(4, static_cast<int>(a->vertices.size()));
    for (int v = 0; v < cell.vertex_count; ++v) cell.vertex[v] = a->vertices[v];
    for (int v = 0; v < cell.vertex_count; ++v) {
      cell.radius = std::max(cell.radius, Distance(cell.vertex[v], points[i].x));
    }
    m_answered += points[i].measure;
    y2 += points[i].measure * a->value * a->value;
    cy2 += points[i].measure * c2 * a->value * a->value;
  }
  *mean_square = m_answered > 0 ? y2 / m_answered : 0;
  *mean_square_cosine = m_all > 0 ? cy2 / m_all : 0;
  return cells;
}

class InterpolatedModel final : public UncertaintyModel {
 public:
  explicit InterpolatedModel(const AdaptiveSpec& spec)
      : spec_(spec), points_(EvaluationDirections(spec.region)) {}

  std::unique_ptr<UncertaintyMap> Map(std::span<const ReadingSoFar> readings) const override {
    const JudgedReadings judged(readings, spec_.judge);
    double f2 = 0, cy2 = 0;
    std::vector<Cell> cells = AnswerCells(points_, judged, &f2, &cy2);
    // The scale of an unknown direction: the answered ones' RMS BRDF (1 sr⁻¹ when there is none
    // or it is 0: the map is then scale-free).
    if (!(f2 > 0)) f2 = judged.MeanSquareValue() > 0 ? judged.MeanSquareValue() : 1.0;
    double m_all = 0;
    for (const EvalPoint& p : points_) m_all += p.measure;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (cells[i].answered) continue;
      const double c2 = points_[i].cosine * points_[i].cosine;
      cells[i].v_interpolation = c2 * kUnknownRelative * kUnknownRelative * f2;
      if (m_all > 0) cy2 += points_[i].measure * c2 * f2 / m_all;
    }
    const bool expanded = spec_.target.kind == TargetKind::kExpandedUncertainty;
    return std::make_unique<InterpolatedMap>(points_, std::move(cells), expanded ? 2.0 : 1.0,
                                             expanded, cy2);
  }

 private:
  AdaptiveSpec spec_;
  std::vector<EvalPoint> points_;
};

}  // namespace

interp::Options JudgeOptions() {
  interp::Options options;
  options.mirror_phi = true;
  return options;
}

std::unique_ptr<UncertaintyModel> MakeInterpolatedModel(const AdaptiveSpec& spec) {
  return std::make_unique<InterpolatedModel>(spec);
}

}  // namespace brdf::adaptive
