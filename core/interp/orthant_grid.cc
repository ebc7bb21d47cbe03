#include "core/interp/orthant_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/interp/octant_cube.h"

namespace brdf::interp {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Relative margins on squared distances: rounding can only widen the lists (see the header).
constexpr double kGrow = 1.0 + 1e-9;
constexpr double kShrink = 1.0 - 1e-9;
// An axis whose extent is below this fraction of the widest one counts as flat (no grid).
constexpr double kFlatExtent = 1e-9;
// Points per orthant that every candidate is compared with (see may_beat_witnesses).
constexpr int kWitnesses = 4;

// The cells of one axis: lines[0] = lo < lines[1] < … < lines[count] = hi, lines[count + 1] = +∞.
struct Axis {
  const std::vector<double>* lines;
  double lo, inv;
  int count;

  // The cell k with lines[k] <= x < lines[k + 1]: −1 below lines[0], count at or above hi.
  // Exact (decided by the lines, not by the rounded division), hence monotone in x.
  int Cell(double x) const {
    const double f = (x - lo) * inv;
    int k = !(f >= 0.0) ? -1 : f >= count ? count : static_cast<int>(f);
    const std::vector<double>& l = *lines;
    while (k >= 0 && x < l[static_cast<std::size_t>(k)]) --k;
    while (k < count && x >= l[static_cast<std::size_t>(k + 1)]) ++k;
    return k;
  }
};

}  // namespace

OrthantGrid::OrthantGrid(const PointCloud& cloud, const std::vector<std::uint32_t>& position_of,
                         const Search& search, const Options& options)
    : dims_(cloud.dims) {
  if (cloud.size() == 0 || cloud.size() > options.max_points || position_of.size() < cloud.size()) {
    return;
  }
  // 3D only: in 4D, with 16 orthants, few cells of the benchmarks' sets kept a list short enough
  // (0.3 % of the queries answered, 0.45 s to build for 4,000 points), so the tree answers.
  if (dims_ == 3) Build<3>(cloud, position_of, search, options);
}

std::size_t OrthantGrid::bytes() const {
  std::size_t total = span_.capacity() * sizeof(Span) + entry_.capacity() * sizeof(std::uint32_t) +
                      block_gap_.capacity() * sizeof(double);
  for (std::size_t j = 0; j < 4; ++j) total += lines_[j].capacity() * sizeof(double);
  return total;
}

template <int D>
void OrthantGrid::Build(const PointCloud& cloud, const std::vector<std::uint32_t>& position_of,
                        const Search& search, const Options& options) {
  constexpr std::size_t kD = D;
  constexpr unsigned kOrthants = 1u << D;
  const std::size_t n = cloud.size();
  const double* scaled = cloud.scaled.data();

  // The box: just above the minimum (so that the lowest points are in the first layer's −
  // orthants), up to the maximum.
  std::array<double, kD> lo{}, hi{}, extent{};
  for (std::size_t j = 0; j < kD; ++j) {
    double mn = kInf, mx = -kInf;
    for (std::size_t i = 0; i < n; ++i) {
      mn = std::min(mn, scaled[i * kD + j]);
      mx = std::max(mx, scaled[i * kD + j]);
    }
    lo[j] = std::nextafter(mn, kInf);
    hi[j] = mx;
    extent[j] = hi[j] - lo[j];
    if (!(extent[j] > 0.0) || !std::isfinite(extent[j])) return;  // flat on an axis: no grid
  }
  // Flat up to rounding on an axis (e.g. half/difference points of in-plane readings, whose
  // θh·sin φd is ±1e-15 at φd = 180°) is flat too: cells as thin as the rounding would make
  // every other axis max_cells wide, a build of seconds for a handful of points.
  const double widest_extent = *std::max_element(extent.begin(), extent.end());
  for (std::size_t j = 0; j < kD; ++j) {
    if (extent[j] < kFlatExtent * widest_extent) return;
  }

  // Cells about as wide on every axis, about cells_per_point · n of them.
  const double target = std::clamp(static_cast<double>(n) * options.cells_per_point, 1.0,
                                   static_cast<double>(options.max_cells));
  double volume = 1.0;
  for (std::size_t j = 0; j < kD; ++j) volume *= extent[j];
  double side = std::pow(volume / target, 1.0 / D);
  std::array<int, kD> count{};
  for (;;) {
    double cells = 1.0;
    for (std::size_t j = 0; j < kD; ++j) {
      count[j] = static_cast<int>(std::clamp(std::round(extent[j] / side), 1.0, 4096.0));
      cells *= count[j];
    }
    if (cells <= static_cast<double>(options.max_cells)) break;
    side *= 1.1;
  }
  std::array<Axis, kD> axes{};
  for (std::size_t j = 0; j < kD; ++j) {
    const int g = count[j];
    std::vector<double>& l = lines_[j];
    l.resize(static_cast<std::size_t>(g) + 2);
    for (int k = 0; k < g; ++k) {
      l[static_cast<std::size_t>(k)] = lo[j] + extent[j] * (static_cast<double>(k) / g);
    }
    l[static_cast<std::size_t>(g)] = hi[j];
    l[static_cast<std::size_t>(g) + 1] = kInf;
    for (int k = 0; k < g; ++k) {
      if (!(l[static_cast<std::size_t>(k)] < l[static_cast<std::size_t>(k) + 1])) {
        lines_ = {};
        return;  // cells too thin to tell apart
      }
    }
    count_[j] = g;
    lo_[j] = lo[j];
    inv_[j] = g / extent[j];
    axes[j] = Axis{&lines_[j], lo[j], inv_[j], g};
  }

  // The points in buckets: one per cell, plus a layer below and above every axis (bucket index
  // cell + 1, from 0 to count + 1), in bucket order, one array per axis.
  std::array<std::size_t, kD> buckets{};
  std::size_t bucket_total = 1;
  for (std::size_t j = 0; j < kD; ++j) {
    buckets[j] = static_cast<std::size_t>(count[j]) + 2;
    bucket_total *= buckets[j];
  }
  std::vector<std::uint32_t> bucket_of(n);
  std::vector<std::uint32_t> start(bucket_total + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t b = 0;
    for (std::size_t j = 0; j < kD; ++j) {
      b = b * buckets[j] + static_cast<std::size_t>(axes[j].Cell(scaled[i * kD + j]) + 1);
    }
    bucket_of[i] = static_cast<std::uint32_t>(b);
    ++start[b + 1];
  }
  // Prefix counts over the buckets: points with bucket index < i on every axis, for (count + 3)^D
  // corners i, so that "no point in this box of buckets" costs 2^D lookups.
  std::array<std::size_t, kD> corners{};
  std::size_t corner_total = 1;
  for (std::size_t j = 0; j < kD; ++j) {
    corners[j] = buckets[j] + 1;
    corner_total *= corners[j];
  }
  std::vector<std::uint32_t> prefix(corner_total, 0);
  {
    std::array<std::size_t, kD> idx{};
    for (std::size_t b = 0; b < bucket_total; ++b) {
      std::size_t rest = b;
      for (std::size_t j = kD; j-- > 0;) {
        idx[j] = rest % buckets[j];
        rest /= buckets[j];
      }
      std::size_t c = 0;
      for (std::size_t j = 0; j < kD; ++j) c = c * corners[j] + idx[j] + 1;
      prefix[c] = start[b + 1];
    }
    // Running sums along each axis in turn.
    std::size_t stride = 1;
    for (std::size_t j = kD; j-- > 0;) {
      for (std::size_t c = 0; c < corner_total; ++c) {
        if ((c / stride) % corners[j] != 0) prefix[c] += prefix[c - stride];
      }
      stride *= corners[j];
    }
  }
  for (std::size_t b = 0; b < bucket_total; ++b) start[b + 1] += start[b];
  std::array<std::vector<double>, kD> bx;
  for (auto& a : bx) a.resize(n);
  std::vector<std::uint32_t> brank(n);
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t at = fill[bucket_of[i]]++;
      for (std::size_t j = 0; j < kD; ++j) bx[j][at] = scaled[i * kD + j];
      brank[at] = static_cast<std::uint32_t>(i);
    }
  }
  // Points in buckets [a_j, c_j] (inclusive) on every axis.
  auto points_in = [&](const std::array<std::size_t, kD>& a, const std::array<std::size_t, kD>& c) {
    std::int64_t total = 0;
    for (unsigned m = 0; m < (1u << D); ++m) {
      std::size_t at = 0;
      int sign = 1;
      for (std::size_t j = 0; j < kD; ++j) {
        const bool upper = ((m >> j) & 1u) == 0;
        at = at * corners[j] + (upper ? c[j] + 1 : a[j]);
        if (!upper) sign = -sign;
      }
      total += sign * static_cast<std::int64_t>(prefix[at]);
    }
    return total;
  };
  // The buckets of orthant o of grid vertex `v` (per-axis vertex indices).
  auto orthant_buckets = [&](const std::array<std::size_t, kD>& v, unsigned o,
                             std::array<std::size_t, kD>& a, std::array<std::size_t, kD>& c) {
    for (std::size_t j = 0; j < kD; ++j) {
      if ((o >> j) & 1u) {
        a[j] = v[j] + 1;
        c[j] = buckets[j] - 1;
      } else {
        a[j] = 0;
        c[j] = v[j];
      }
    }
  };
  // Per grid vertex v (0 … count on every axis): bit o set when orthant o of the vertex holds a
  // point: + on axis j is cell >= v_j (bucket >= v_j + 1), − is cell < v_j (bucket <= v_j).
  std::array<std::size_t, kD> vertices{};
  std::size_t vertex_total = 1;
  for (std::size_t j = 0; j < kD; ++j) {
    vertices[j] = static_cast<std::size_t>(count[j]) + 1;
    vertex_total *= vertices[j];
  }
  std::vector<std::uint16_t> occupied(vertex_total, 0);
  {
    std::array<std::size_t, kD> v{}, a{}, c{};
    for (std::size_t at = 0; at < vertex_total; ++at) {
      std::size_t rest = at;
      for (std::size_t j = kD; j-- > 0;) {
        v[j] = rest % vertices[j];
        rest /= vertices[j];
      }
      unsigned mask = 0;
      for (unsigned o = 0; o < kOrthants; ++o) {
        orthant_buckets(v, o, a, c);
        if (points_in(a, c) > 0) mask |= 1u << o;
      }
      occupied[at] = static_cast<std::uint16_t>(mask);
    }
  }

  cells_ = 1;
  for (std::size_t j = 0; j < kD; ++j) cells_ *= static_cast<std::size_t>(count[j]);
  span_.assign(cells_, Span{});
  entry_.reserve(cells_ * 32);

  // Visits every bucketed point in buckets [a_j, c_j] (inclusive) on every axis, until `visit`
  // returns false.
  auto for_buckets = [&](const std::array<std::size_t, kD>& a, const std::array<std::size_t, kD>& c,
                         auto&& visit) {
    // The last axis's buckets are contiguous.
    std::array<std::size_t, kD> idx = a;
    for (;;) {
      std::size_t row = 0;
      for (std::size_t j = 0; j + 1 < kD; ++j) row = row * buckets[j] + idx[j];
      row *= buckets[kD - 1];
      const std::uint32_t from = start[row + a[kD - 1]];
      const std::uint32_t to = start[row + c[kD - 1] + 1];
      for (std::uint32_t i = from; i < to; ++i) {
        if (!visit(i)) return;
      }
      std::size_t j = kD - 1;
      for (;;) {
        if (j == 0) return;
        --j;
        if (++idx[j] <= c[j]) break;
        idx[j] = a[j];
      }
    }
  };
  std::vector<std::uint32_t> stamp(n, 0);  // the last cell (+ 1) that considered a point

  // The tree's winners at every grid vertex (the witnesses' source), and where each point sits
  // in bucket order.
  std::vector<std::uint32_t> bucket_at(n);
  for (std::uint32_t i = 0; i < n; ++i) bucket_at[brank[i]] = i;
  std::vector<std::uint32_t> vertex_winner(vertex_total * kOrthants, kNoPoint);
  {
    std::array<std::size_t, kD> v{};
    std::array<double, kD> p{};
    OrthantWinners winners;
    for (std::size_t at = 0; at < vertex_total; ++at) {
      std::size_t rest = at;
      for (std::size_t j = kD; j-- > 0;) {
        v[j] = rest % vertices[j];
        rest /= vertices[j];
        p[j] = lines_[j][v[j]];
      }
      search(p.data(), winners);
      for (unsigned o = 0; o < kOrthants; ++o) vertex_winner[at * kOrthants + o] = winners.rank[o];
    }
  }
  std::array<std::size_t, kD> k{};
  struct Pick {
    double gap2;  // squared distance from the cell (computed; never above the true one by more
                  // than rounding)
    std::uint32_t rank;
    std::uint32_t at;  // bucket order
  };
  std::vector<Pick> picked;
  for (std::size_t cell = 0; cell < cells_; ++cell) {
    {
      std::size_t rest = cell;
      for (std::size_t j = kD; j-- > 0;) {
        k[j] = rest % static_cast<std::size_t>(count[j]);
        rest /= static_cast<std::size_t>(count[j]);
      }
    }
    std::array<double, kD> cl{}, ch{};
    double widest = 0.0;
    for (std::size_t j = 0; j < kD; ++j) {
      cl[j] = lines_[j][k[j]];
      ch[j] = lines_[j][k[j] + 1];
      widest = std::max(widest, ch[j] - cl[j]);
    }
    // Which orthants need candidates. An orthant empty at the near corner but not at the far one
    // (a hole or an edge of the data) has no bounding point: if few points can lie in it for some
    // query of the cell (those in the far corner's orthant), all of them are its candidates
    // ("whole"); otherwise the cell keeps no list.
    unsigned need = 0, whole = 0;
    bool hole = false;
    std::array<std::array<std::size_t, kD>, kMaxOrthants> far_vertex{};
    for (unsigned o = 0; o < kOrthants && !hole; ++o) {
      std::size_t near = 0, far = 0;
      for (std::size_t j = 0; j < kD; ++j) {
        const std::size_t plus = (o >> j) & 1u;
        near = near * vertices[j] + k[j] + plus;
        far = far * vertices[j] + k[j] + 1 - plus;
        far_vertex[o][j] = k[j] + 1 - plus;
      }
      if (((occupied[far] >> o) & 1u) == 0) continue;  // empty for every query of the cell
      need |= 1u << o;
      if (((occupied[near] >> o) & 1u) != 0) continue;
      std::array<std::size_t, kD> a{}, c{};
      orthant_buckets(far_vertex[o], o, a, c);
      if (points_in(a, c) > static_cast<std::int64_t>(options.max_list / 2)) {
        hole = true;
      } else {
        whole |= 1u << o;
      }
    }
    if (hole) {
      ++unlisted_[0];
      continue;
    }
    // U per orthant: the distance from the far corner to a point in the near corner's orthant
    // (any such point bounds it; the search widens until one is found for every orthant).
    std::array<double, kMaxOrthants> bound;
    bound.fill(kInf);
    // Per orthant, the few points in it for every query of the cell ("witnesses") nearest to the
    // far corner: a candidate must be at least as near as each of them to some query of the cell.
    std::array<std::array<std::uint32_t, kWitnesses>, kMaxOrthants> witness{};
    std::array<std::array<double, kWitnesses>, kMaxOrthants> witness_d2{};
    std::array<int, kMaxOrthants> witnesses{};
    auto add_witness = [&](unsigned o, std::uint32_t i, double d2) {
      int worst = 0;
      for (int w = 0; w < witnesses[o]; ++w) {
        if (witness[o][w] == i) return;  // met again by a wider pass
        if (witness_d2[o][w] > witness_d2[o][worst]) worst = w;
      }
      if (witnesses[o] < kWitnesses) {
        worst = witnesses[o]++;
      } else if (!(d2 < witness_d2[o][worst])) {
        return;
      }
      witness[o][worst] = i;
      witness_d2[o][worst] = d2;
    };
    // False when, for every query of the cell, point i is farther than some witness of o: then
    // it never wins o. |q − p|² − |q − w|² is linear in q, so its least value over the cell is at
    // the corner chosen axis by axis; the margin (relative to |f − w|², which bounds both terms
    // wherever it matters) covers the rounding of both sums.
    auto may_beat_witnesses = [&](std::uint32_t i, unsigned o) {
      for (int w = 0; w < witnesses[o]; ++w) {
        const std::uint32_t at = witness[o][w];
        double dp = 0.0, dw = 0.0;
        for (std::size_t j = 0; j < kD; ++j) {
          const double x = bx[j][i], y = bx[j][at];
          const double corner = x > y ? ch[j] : cl[j];
          dp += RoundedSquare(corner - x);
          dw += RoundedSquare(corner - y);
        }
        if (dp > dw + 1e-9 * witness_d2[o][w]) return false;
      }
      return true;
    };
    // The witnesses: the tree's winner of o at the near corner, and at the vertices one step
    // farther in o's direction on each axis (their orthant o lies inside the near corner's).
    bool lost = false;
    for (unsigned rest = need & ~whole; rest != 0 && !lost; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      std::array<std::size_t, kD> v{};
      for (std::size_t j = 0; j < kD; ++j) v[j] = k[j] + ((o >> j) & 1u);
      for (std::size_t step = 0; step <= kD; ++step) {
        std::array<std::size_t, kD> u = v;
        if (step < kD) {
          if ((o >> step) & 1u) {
            if (u[step] + 1 >= vertices[step]) continue;
            ++u[step];
          } else {
            if (u[step] == 0) continue;
            --u[step];
          }
        }
        std::size_t at = 0;
        for (std::size_t j = 0; j < kD; ++j) at = at * vertices[j] + u[j];
        const std::uint32_t r = vertex_winner[at * kOrthants + o];
        if (r == kNoPoint) continue;
        const std::uint32_t i = bucket_at[r];
        double d2 = 0.0;
        for (std::size_t j = 0; j < kD; ++j) {
          const double f = ((o >> j) & 1u) ? cl[j] : ch[j];
          d2 += RoundedSquare(bx[j][i] - f);
        }
        bound[o] = std::min(bound[o], d2);
        add_witness(o, i, d2);
      }
      lost = witnesses[o] == 0;  // the counts said o is occupied at the near corner
    }
    if (lost) {
      ++unlisted_[0];
      continue;
    }
    double widest_bound = 0.0;
    for (unsigned o = 0; o < kOrthants; ++o) {
      if (((need & ~whole) >> o) & 1u) {
        bound[o] *= kGrow / kShrink;
        widest_bound = std::max(widest_bound, bound[o]);
      }
    }
    // The candidates: points that can lie in a needed orthant o for some query of the cell and
    // are within o's bound of the cell.
    const double reach = std::sqrt(widest_bound) * (1.0 + 1e-6);
    if (!(reach <= options.max_reach * widest)) {
      ++unlisted_[1];
      continue;
    }
    picked.clear();
    bool too_many = false;
    const auto stamp_of = static_cast<std::uint32_t>(cell + 1);
    auto consider = [&](std::uint32_t i) {
      if (stamp[i] == stamp_of) return true;
      stamp[i] = stamp_of;
      double gap2 = 0.0;
      unsigned lt = 0, ge = 0;
      for (std::size_t j = 0; j < kD; ++j) {
        const double x = bx[j][i];
        const double gap = x < cl[j] ? cl[j] - x : x > ch[j] ? x - ch[j] : 0.0;
        gap2 += RoundedSquare(gap);
        lt |= static_cast<unsigned>(x < ch[j]) << j;
        ge |= static_cast<unsigned>(x >= cl[j]) << j;
      }
      for (unsigned rest = need; rest != 0; rest &= rest - 1) {
        const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
        // o is reachable when, on every axis, the point can be on o's side.
        if (((o & ~ge) | (~o & ~lt)) & ((1u << D) - 1u)) continue;
        if (((whole >> o) & 1u) != 0 || (gap2 * kShrink <= bound[o] && may_beat_witnesses(i, o))) {
          picked.push_back(Pick{gap2, brank[i], i});
          break;
        }
      }
      too_many = picked.size() > options.max_list;
      return !too_many;
    };
    // Orthant by orthant: its candidates lie on its sides of the cell, within its own bound.
    for (unsigned rest = need & ~whole; rest != 0 && !too_many; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      const double r = std::sqrt(bound[o]) * (1.0 + 1e-6);
      std::array<std::size_t, kD> a{}, c{};
      for (std::size_t j = 0; j < kD; ++j) {
        const bool plus = (o >> j) & 1u;
        a[j] = static_cast<std::size_t>(axes[j].Cell(plus ? cl[j] : cl[j] - r) + 1);
        c[j] = static_cast<std::size_t>(axes[j].Cell(plus ? ch[j] + r : ch[j]) + 1);
      }
      for_buckets(a, c, consider);
    }
    for (unsigned rest = whole; rest != 0 && !too_many; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      std::array<std::size_t, kD> a{}, c{};
      orthant_buckets(far_vertex[o], o, a, c);
      for_buckets(a, c, consider);
    }
    if (too_many) {
      ++unlisted_[2];
      continue;
    }
    // Nearest to the cell first: the scan meets the likely winners early and can stop once the
    // remaining entries are all farther than every needed orthant's best.
    std::sort(picked.begin(), picked.end(), [](const Pick& a, const Pick& b) {
      return a.gap2 < b.gap2 || (a.gap2 == b.gap2 && a.rank < b.rank);
    });
    // Padded to whole blocks of 8 with copies of the last entry (a copy ties with itself: never
    // better, so it changes nothing).
    const std::size_t padded = (picked.size() + 7) / 8 * 8;
    span_[cell] =
        Span{static_cast<std::uint32_t>(entry_.size()), static_cast<std::uint32_t>(padded), need};
    for (std::size_t e = 0; e < padded; ++e) {
      const Pick& pick = picked[std::min(e, picked.size() - 1)];
      entry_.push_back(position_of[pick.rank]);
      // The bound the scan compares with, shrunk so that rounding in the query's distance (a few
      // ulps) cannot make an entry look nearer than its bound says.
      if (e % 8 == 0) block_gap_.push_back(pick.gap2 * kShrink);
    }
    ++listed_cells_;
  }
  entry_.shrink_to_fit();
  block_gap_.shrink_to_fit();
}

template void OrthantGrid::Build<3>(const PointCloud&, const std::vector<std::uint32_t>&,
                                    const Search&, const Options&);

}  // namespace brdf::interp
