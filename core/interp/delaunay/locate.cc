#include "core/interp/delaunay/locate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace brdf::interp {
namespace {

// A query whose barycentric coordinate is above −kStepEps for a face is on the inner side of
// it (scipy's tolerance). Rounding on the hull is forgiven further: the query counts as outside
// only when it is beyond a hull face by more than kHullEps (relative to the simplex), so queries
// on the data's boundary planes (θ = 0, φ = 0, ...) are not lost to the last bit.
constexpr double kStepEps = 100 * std::numeric_limits<double>::epsilon();
constexpr double kHullEps = 1e-10;
// A simplex whose edge matrix has a reciprocal condition number below this is flat.
constexpr double kFlatRcond = 1000 * std::numeric_limits<double>::epsilon();

template <int D>
inline void Barycentric(const double* transform, const double* x, double* c) {
  double dx[D];
  for (int j = 0; j < D; ++j) dx[j] = x[j] - transform[D * D + j];
  double sum = 0;
  for (int i = 0; i < D; ++i) {
    double ci = 0;
    for (int j = 0; j < D; ++j) ci += transform[i * D + j] * dx[j];
    c[i] = ci;
    sum += ci;
  }
  c[D] = 1 - sum;
}

// Clamps the rounding noise out of inside weights so that they are >= 0 and sum to 1.
template <int D>
inline SimplexLocation Inside(std::int32_t simplex, const double* c) {
  SimplexLocation loc;
  loc.inside = true;
  loc.simplex = simplex;
  double sum = 0;
  for (int m = 0; m <= D; ++m) {
    loc.weights[m] = std::max(c[m], 0.0);
    sum += loc.weights[m];
  }
  for (int m = 0; m <= D; ++m) loc.weights[m] /= sum;
  return loc;
}

inline SimplexLocation Outside(std::int32_t simplex) {
  SimplexLocation loc;
  loc.simplex = simplex;
  return loc;
}

// Inverts the dims×dims matrix `a` (row-major) by Gauss–Jordan elimination with partial
// pivoting. Returns the reciprocal 1-norm condition number, 0 when singular.
double InvertMatrix(int n, const double* a, double* inverse) {
  double work[4][8];
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      work[i][j] = a[i * n + j];
      work[i][n + j] = i == j ? 1.0 : 0.0;
    }
  }
  for (int col = 0; col < n; ++col) {
    int pivot = col;
    for (int r = col + 1; r < n; ++r) {
      if (std::abs(work[r][col]) > std::abs(work[pivot][col])) pivot = r;
    }
    if (work[pivot][col] == 0.0 || !std::isfinite(work[pivot][col])) return 0.0;
    if (pivot != col) std::swap(work[pivot], work[col]);
    const double scale = 1.0 / work[col][col];
    for (int j = 0; j < 2 * n; ++j) work[col][j] *= scale;
    for (int r = 0; r < n; ++r) {
      if (r == col) continue;
      const double f = work[r][col];
      if (f == 0.0) continue;
      for (int j = 0; j < 2 * n; ++j) work[r][j] -= f * work[col][j];
    }
  }
  double norm_a = 0;
  double norm_inv = 0;
  for (int j = 0; j < n; ++j) {
    double col_a = 0;
    double col_inv = 0;
    for (int i = 0; i < n; ++i) {
      inverse[i * n + j] = work[i][n + j];
      col_a += std::abs(a[i * n + j]);
      col_inv += std::abs(work[i][n + j]);
    }
    norm_a = std::max(norm_a, col_a);
    norm_inv = std::max(norm_inv, col_inv);
  }
  const double rcond = 1.0 / (norm_a * norm_inv);
  return std::isfinite(rcond) ? rcond : 0.0;
}

template <int D>
const double* PointAt(std::span<const double> points, std::int32_t v) {
  return &points[static_cast<std::size_t>(v) * D];
}

// Bounding box of the triangulated points.
template <int D>
void BoundingBox(std::span<const double> points, const std::vector<std::int32_t>& verts,
                 std::array<double, 4>& lower, std::array<double, 4>& upper) {
  for (std::size_t i = 0; i < D; ++i) {
    lower[i] = std::numeric_limits<double>::infinity();
    upper[i] = -std::numeric_limits<double>::infinity();
  }
  for (std::int32_t v : verts) {
    for (std::size_t i = 0; i < D; ++i) {
      lower[i] = std::min(lower[i], PointAt<D>(points, v)[i]);
      upper[i] = std::max(upper[i], PointAt<D>(points, v)[i]);
    }
  }
}

// The simplices ordered along a Morton curve through their centroids (the triangulation's
// simplex at each place): a walk's next simplex, and the simplices of nearby queries, are then
// mostly a few cache lines away, not anywhere in tens of megabytes.
template <int D>
std::vector<std::int32_t> MortonOrder(std::span<const double> points,
                                      const std::vector<std::int32_t>& verts,
                                      const std::array<double, 4>& lower,
                                      const std::array<double, 4>& upper) {
  constexpr std::size_t K = D + 1;
  const std::size_t simplex_count = verts.size() / K;
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed(simplex_count);
  constexpr int kBits = 64 / D;
  const double levels = static_cast<double>((std::uint64_t{1} << kBits) - 1);
  for (std::size_t s = 0; s < simplex_count; ++s) {
    std::uint64_t q[D];
    for (std::size_t i = 0; i < D; ++i) {
      double c = 0;
      for (std::size_t m = 0; m < K; ++m) c += PointAt<D>(points, verts[s * K + m])[i];
      const double extent = upper[i] - lower[i];
      const double t = extent > 0 ? (c / K - lower[i]) / extent : 0.0;
      q[i] = static_cast<std::uint64_t>(std::clamp(t, 0.0, 1.0) * levels);
    }
    std::uint64_t key = 0;
    for (int bit = kBits - 1; bit >= 0; --bit) {
      for (std::size_t i = 0; i < D; ++i) key = (key << 1) | ((q[i] >> bit) & 1);
    }
    keyed[s] = {key, static_cast<std::int32_t>(s)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::int32_t> order(simplex_count);
  for (std::size_t s = 0; s < simplex_count; ++s) order[s] = keyed[s].second;
  return order;
}

}  // namespace

template <>
const std::vector<SimplexLocator::Record<3>>& SimplexLocator::records<3>() const {
  return records3_;
}
template <>
const std::vector<SimplexLocator::Record<4>>& SimplexLocator::records<4>() const {
  return records4_;
}
template <>
std::vector<SimplexLocator::Record<3>>& SimplexLocator::records<3>() {
  return records3_;
}
template <>
std::vector<SimplexLocator::Record<4>>& SimplexLocator::records<4>() {
  return records4_;
}

Result<SimplexLocator> SimplexLocator::Build(std::span<const double> points, int dims,
                                             QhullTriangulation triangulation) {
  if (dims != 3 && dims != 4) {
    return InvalidArgument("Delaunay point location: " + std::to_string(dims) +
                           " dimensions; only 3 and 4 are supported");
  }
  const std::size_t k = static_cast<std::size_t>(dims) + 1;
  const std::size_t point_count = points.size() / static_cast<std::size_t>(dims);
  const auto& verts = triangulation.vertices;
  const auto& nbrs = triangulation.neighbours;
  if (verts.empty() || verts.size() % k != 0 || nbrs.size() != verts.size()) {
    return Internal("Delaunay point location: malformed triangulation (" +
                    std::to_string(verts.size()) + " vertex and " + std::to_string(nbrs.size()) +
                    " neighbour entries for " + std::to_string(dims) + "-D simplices)");
  }
  const std::size_t simplex_count = verts.size() / k;
  if (simplex_count > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return InvalidArgument("Delaunay point location: " + std::to_string(simplex_count) +
                           " simplices exceed the index range; thin the sample set");
  }

  // Topology, checked: indices in range, and every neighbour shares the face and points back.
  for (std::size_t s = 0; s < simplex_count; ++s) {
    for (std::size_t m = 0; m < k; ++m) {
      const std::int32_t v = verts[s * k + m];
      const std::int32_t n = nbrs[s * k + m];
      if (v < 0 || static_cast<std::size_t>(v) >= point_count || n < -1 ||
          (n >= 0 && static_cast<std::size_t>(n) >= simplex_count)) {
        return Internal("Delaunay point location: simplex " + std::to_string(s) +
                        " refers to vertex " + std::to_string(v) + " / neighbour " +
                        std::to_string(n) + " out of range");
      }
    }
  }
  for (std::size_t s = 0; s < simplex_count; ++s) {
    for (std::size_t m = 0; m < k; ++m) {
      const std::int32_t n = nbrs[s * k + m];
      if (n < 0) continue;
      const auto* nv = &verts[static_cast<std::size_t>(n) * k];
      std::size_t shared = 0;
      bool points_back = false;
      for (std::size_t i = 0; i < k; ++i) {
        if (i != m && std::find(nv, nv + k, verts[s * k + i]) != nv + k) ++shared;
        if (nbrs[static_cast<std::size_t>(n) * k + i] == static_cast<std::int32_t>(s)) {
          points_back = true;
        }
      }
      if (shared != k - 1 || !points_back) {
        return Internal("Delaunay point location: simplices " + std::to_string(s) + " and " +
                        std::to_string(n) + " are listed as neighbours but do not share a face");
      }
    }
  }
  return dims == 3 ? BuildFor<3>(points, triangulation) : BuildFor<4>(points, triangulation);
}

template <int D>
Result<SimplexLocator> SimplexLocator::BuildFor(std::span<const double> points,
                                                const QhullTriangulation& triangulation) {
  const std::size_t simplex_count = triangulation.vertices.size() / (D + 1);
  SimplexLocator loc;
  loc.dims_ = D;
  loc.simplex_count_ = simplex_count;
  BoundingBox<D>(points, triangulation.vertices, loc.lower_, loc.upper_);
  loc.BuildRecords<D>(points, triangulation,
                      MortonOrder<D>(points, triangulation.vertices, loc.lower_, loc.upper_));
  if (loc.degenerate_count_ == simplex_count) {
    return InvalidArgument("Delaunay point location: all " + std::to_string(simplex_count) +
                           " simplices are flat; the samples lie on a hyperplane");
  }

  // A legitimate walk crosses the triangulation at most a few times its diameter in simplices.
  loc.max_steps_ =
      64 + 16 * static_cast<int>(std::ceil(std::pow(static_cast<double>(simplex_count), 1.0 / D)));
  loc.BuildGrid<D>(points.size() / D);
  return loc;
}

// Records in curve order (`order`: the triangulation's simplex at each place): topology
// (renumbered) and barycentric transforms; flat simplices counted.
template <int D>
void SimplexLocator::BuildRecords(std::span<const double> points,
                                  const QhullTriangulation& triangulation,
                                  const std::vector<std::int32_t>& order) {
  constexpr std::size_t K = D + 1;
  const auto& verts = triangulation.vertices;
  const auto& nbrs = triangulation.neighbours;
  const std::size_t simplex_count = order.size();
  std::vector<std::int32_t> new_index(simplex_count);
  for (std::size_t s = 0; s < simplex_count; ++s) {
    new_index[static_cast<std::size_t>(order[s])] = static_cast<std::int32_t>(s);
  }
  auto& recs = records<D>();
  recs.resize(simplex_count);
  for (std::size_t s = 0; s < simplex_count; ++s) {
    const auto old = static_cast<std::size_t>(order[s]);
    Record<D>& r = recs[s];
    for (std::size_t m = 0; m < K; ++m) {
      r.vertices[m] = verts[old * K + m];
      const std::int32_t n = nbrs[old * K + m];
      r.neighbours[m] = n < 0 ? -1 : new_index[static_cast<std::size_t>(n)];
    }
    const double* last = PointAt<D>(points, r.vertices[D]);
    double edges[D * D];
    for (int j = 0; j < D; ++j) {
      const double* vj = PointAt<D>(points, r.vertices[j]);
      for (int i = 0; i < D; ++i) edges[i * D + j] = vj[i] - last[i];
    }
    const double rcond = InvertMatrix(D, edges, r.transform);
    for (int i = 0; i < D; ++i) r.transform[D * D + i] = last[i];
    if (rcond < kFlatRcond) {
      r.transform[0] = std::numeric_limits<double>::quiet_NaN();
      ++degenerate_count_;
    }
  }
}

bool SimplexLocator::IsDegenerate(std::int32_t simplex) const {
  const auto s = static_cast<std::size_t>(simplex);
  return std::isnan(dims_ == 3 ? records3_[s].transform[0] : records4_[s].transform[0]);
}

bool SimplexLocator::InBounds(const double* x) const {
  for (int i = 0; i < dims_; ++i) {
    // Written so that NaN is out of bounds.
    if (!(x[i] >= lower_[i] && x[i] <= upper_[i])) return false;
  }
  return true;
}

std::int32_t SimplexLocator::GridStart(const double* x) const {
  std::int64_t cell = 0;
  for (int i = 0; i < dims_; ++i) {
    auto c = static_cast<std::int64_t>((x[i] - lower_[i]) * cells_per_unit_[i]);
    c = std::clamp<std::int64_t>(c, 0, cell_counts_[i] - 1);
    cell = cell * cell_counts_[i] + c;
  }
  return grid_[static_cast<std::size_t>(cell)];
}

template <int D>
void SimplexLocator::BuildGrid(std::size_t point_count) {
  // About eight cells per point (measured: fewer steps outweigh the larger table); the cell
  // centre's simplex is then a step or two from any query in the cell. Cells follow the box's
  // aspect ratio.
  const double target = std::clamp(8.0 * static_cast<double>(point_count), 1.0, 8.0e6);
  double volume = 1;
  for (int i = 0; i < D; ++i) volume *= std::max(upper_[i] - lower_[i], 1e-300);
  const double per_unit = std::pow(target / volume, 1.0 / D);
  std::size_t total = 1;
  for (int i = 0; i < D; ++i) {
    const double extent = upper_[i] - lower_[i];
    const double n = std::clamp(std::round(extent * per_unit), 1.0, 4096.0);
    cell_counts_[i] = static_cast<std::int64_t>(n);
    cells_per_unit_[i] = extent > 0 ? n / extent : 0.0;
    total *= static_cast<std::size_t>(n);
  }
  grid_.assign(total, 0);

  // Cells in row-major order, each walk starting from the previous cell's answer: neighbouring
  // cells are a few simplices apart, so the whole grid costs a few steps per cell.
  std::int32_t start = 0;
  while (IsDegenerate(start)) ++start;
  std::array<std::int64_t, D> index{};
  double centre[D];
  for (std::size_t cell = 0; cell < total; ++cell) {
    for (int i = 0; i < D; ++i) {
      centre[i] = lower_[i] + (static_cast<double>(index[i]) + 0.5) /
                                  (cells_per_unit_[i] > 0 ? cells_per_unit_[i] : 1.0);
    }
    const SimplexLocation loc = Walk<D>(centre, start);
    if (loc.simplex >= 0 && !IsDegenerate(loc.simplex)) start = loc.simplex;
    grid_[cell] = start;
    for (int i = D - 1; i >= 0; --i) {
      if (++index[i] < cell_counts_[i]) break;
      index[i] = 0;
    }
  }
}

template <int D>
SimplexLocation SimplexLocator::Walk(const double* x, std::int32_t start) const {
  constexpr int K = D + 1;
  std::int32_t s = start;
  std::int32_t previous = -1;
  double c[K];
  const Record<D>* all = records<D>().data();
  for (int step = 0; step < max_steps_; ++step) {
    const double* t = all[s].transform;
    const std::int32_t* neighbours = all[s].neighbours;
    if (std::isnan(t[0])) {
      // A flat simplex has no barycentric coordinates of its own. Leave it for a solid
      // neighbour that has the query on its side of the shared face (judged in that
      // neighbour's coordinates); failing that, for another flat neighbour, rotating the choice
      // so that a cluster of flat simplices is not circled forever.
      std::int32_t next = -1;
      double best = -kStepEps;
      for (int i = 0; i < K; ++i) {
        const std::int32_t n = neighbours[i];
        if (n < 0 || n == previous || std::isnan(all[n].transform[0])) continue;
        Barycentric<D>(all[n].transform, x, c);
        for (int j = 0; j < K; ++j) {
          if (all[n].neighbours[j] == s && c[j] >= best) {
            best = c[j];
            next = n;
          }
        }
      }
      for (int i = 0; i < K && next < 0; ++i) {
        const std::int32_t n = neighbours[(step + i) % K];
        if (n >= 0 && n != previous) next = n;
      }
      if (next < 0) break;
      previous = s;
      s = next;
      continue;
    }
    Barycentric<D>(t, x, c);
    int exit = -1;
    double most_negative = -kStepEps;
    for (int m = 0; m < K; ++m) {
      if (c[m] >= -kStepEps) continue;
      if (neighbours[m] < 0) {
        if (c[m] < -kHullEps) return Outside(s);  // beyond a hull face: outside the hull
      } else if (c[m] < most_negative) {
        most_negative = c[m];
        exit = m;
      }
    }
    if (exit < 0) return Inside<D>(s, c);
    previous = s;
    s = neighbours[exit];
  }
  return Scan<D>(x);
}

template <int D>
SimplexLocation SimplexLocator::Scan(const double* x) const {
  constexpr int K = D + 1;
  std::int32_t best = -1;
  double best_min = -std::numeric_limits<double>::infinity();
  double best_c[K] = {};
  double c[K];
  const auto& all = records<D>();
  for (std::size_t s = 0; s < simplex_count_; ++s) {
    const double* t = all[s].transform;
    if (std::isnan(t[0])) continue;
    Barycentric<D>(t, x, c);
    const double lowest = *std::min_element(c, c + K);
    if (lowest > best_min) {
      best_min = lowest;
      best = static_cast<std::int32_t>(s);
      std::copy(c, c + K, best_c);
      if (lowest >= -kStepEps) break;
    }
  }
  if (best >= 0 && best_min >= -kHullEps) return Inside<D>(best, best_c);
  return Outside(best);
}

template <int D>
SimplexLocation SimplexLocator::From(const double* x, std::int32_t hint) const {
  constexpr int K = D + 1;
  if (hint >= 0 && static_cast<std::size_t>(hint) < simplex_count_ && !IsDegenerate(hint)) {
    double c[K];
    Barycentric<D>(records<D>()[static_cast<std::size_t>(hint)].transform, x, c);
    const double lowest = *std::min_element(c, c + K);
    if (lowest >= -kStepEps) return Inside<D>(hint, c);
  }
  return Walk<D>(x, GridStart(x));
}

SimplexLocation SimplexLocator::Locate(std::span<const double> x) const {
  return LocateFrom(x, -1);
}

SimplexLocation SimplexLocator::LocateFrom(std::span<const double> x, std::int32_t hint) const {
  if (x.size() != static_cast<std::size_t>(dims_) || !InBounds(x.data())) return Outside(-1);
  return dims_ == 3 ? From<3>(x.data(), hint) : From<4>(x.data(), hint);
}

SimplexLocation SimplexLocator::LocateByScan(std::span<const double> x) const {
  if (x.size() != static_cast<std::size_t>(dims_) || !InBounds(x.data())) return Outside(-1);
  return dims_ == 3 ? Scan<3>(x.data()) : Scan<4>(x.data());
}

}  // namespace brdf::interp
