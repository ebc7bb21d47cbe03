#include "core/interp/search/orthant_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/interp/octant/cube.h"

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

// The build's working state: the box and its lines, the points in buckets with their prefix
// counts, which orthants of each grid vertex hold points, and the tree's winners there. Then, cell
// by cell (ListCell), the phases that decide the cell's list or why it keeps none.
template <int D>
class OrthantGrid::Builder {
 public:
  Builder(OrthantGrid& grid, const PointCloud& cloud, const std::vector<std::uint32_t>& position_of,
          const Search& search, const Options& options)
      : grid_(grid),
        position_of_(position_of),
        search_(search),
        options_(options),
        n_(cloud.size()),
        scaled_(cloud.scaled.data()) {}

  void Run() {
    if (!FindBox()) return;
    ChooseCellCounts();
    if (!DrawLines()) return;
    BucketPoints();
    CountPrefixes();
    SortIntoBuckets();
    MarkOccupiedOrthants();
    FindVertexWinners();
    grid_.cells_ = 1;
    for (std::size_t j = 0; j < kD; ++j) grid_.cells_ *= static_cast<std::size_t>(count_[j]);
    grid_.span_.assign(grid_.cells_, Span{});
    grid_.entry_.reserve(grid_.cells_ * 32);
    for (std::size_t cell = 0; cell < grid_.cells_; ++cell) ListCell(cell);
    grid_.entry_.shrink_to_fit();
    grid_.block_gap_.shrink_to_fit();
  }

 private:
  static constexpr std::size_t kD = D;
  static constexpr unsigned kOrthants = 1u << D;
  using Index = std::array<std::size_t, kD>;

  // A candidate of the cell being listed.
  struct Pick {
    double gap2;  // squared distance from the cell (computed; never above the true one by more
                  // than rounding)
    std::uint32_t rank;
    std::uint32_t at;  // bucket order
  };
  // What the phases of one cell's list find out (fresh for every cell).
  struct CellWork {
    Index k{};  // the cell's index on each axis
    std::array<double, kD> cl{}, ch{};
    double widest = 0.0;  // the cell's widest side
    // Orthants that need candidates, and those whose candidates are all their points ("whole").
    unsigned need = 0, whole = 0;
    std::array<Index, kMaxOrthants> far_vertex{};
    // U per orthant: the distance from the far corner to a point in the near corner's orthant.
    std::array<double, kMaxOrthants> bound;
    // Per orthant, the few points in it for every query of the cell ("witnesses") nearest to the
    // far corner: a candidate must be at least as near as each of them to some query of the cell.
    std::array<std::array<std::uint32_t, kWitnesses>, kMaxOrthants> witness{};
    std::array<std::array<double, kWitnesses>, kMaxOrthants> witness_d2{};
    std::array<int, kMaxOrthants> witnesses{};
    CellWork() { bound.fill(kInf); }
  };

  // Per-axis indices of flat index `at` over `sizes` (row-major, last axis fastest).
  static void Unflatten(std::size_t at, const Index& sizes, Index& out) {
    for (std::size_t j = kD; j-- > 0;) {
      out[j] = at % sizes[j];
      at /= sizes[j];
    }
  }

  // The box: just above the minimum (so that the lowest points are in the first layer's −
  // orthants), up to the maximum. False when the cloud is flat on an axis: no grid.
  bool FindBox() {
    for (std::size_t j = 0; j < kD; ++j) {
      double mn = kInf, mx = -kInf;
      for (std::size_t i = 0; i < n_; ++i) {
        mn = std::min(mn, scaled_[i * kD + j]);
        mx = std::max(mx, scaled_[i * kD + j]);
      }
      lo_[j] = std::nextafter(mn, kInf);
      hi_[j] = mx;
      extent_[j] = hi_[j] - lo_[j];
      if (!(extent_[j] > 0.0) || !std::isfinite(extent_[j])) return false;
    }
    // Flat up to rounding on an axis (e.g. half/difference points of in-plane readings, whose
    // θh·sin φd is ±1e-15 at φd = 180°) is flat too: cells as thin as the rounding would make
    // every other axis max_cells wide, a build of seconds for a handful of points.
    const double widest_extent = *std::max_element(extent_.begin(), extent_.end());
    for (std::size_t j = 0; j < kD; ++j) {
      if (extent_[j] < kFlatExtent * widest_extent) return false;
    }
    return true;
  }

  // Cells about as wide on every axis, about cells_per_point · n of them.
  void ChooseCellCounts() {
    const double target = std::clamp(static_cast<double>(n_) * options_.cells_per_point, 1.0,
                                     static_cast<double>(options_.max_cells));
    double volume = 1.0;
    for (std::size_t j = 0; j < kD; ++j) volume *= extent_[j];
    double side = std::pow(volume / target, 1.0 / D);
    for (;;) {
      double cells = 1.0;
      for (std::size_t j = 0; j < kD; ++j) {
        count_[j] = static_cast<int>(std::clamp(std::round(extent_[j] / side), 1.0, 4096.0));
        cells *= count_[j];
      }
      if (cells <= static_cast<double>(options_.max_cells)) break;
      side *= 1.1;
    }
  }

  // The grid's lines, cells per axis and scale. False (and no lines) when cells are too thin to
  // tell apart.
  bool DrawLines() {
    for (std::size_t j = 0; j < kD; ++j) {
      const int g = count_[j];
      std::vector<double>& l = grid_.lines_[j];
      l.resize(static_cast<std::size_t>(g) + 2);
      for (int k = 0; k < g; ++k) {
        l[static_cast<std::size_t>(k)] = lo_[j] + extent_[j] * (static_cast<double>(k) / g);
      }
      l[static_cast<std::size_t>(g)] = hi_[j];
      l[static_cast<std::size_t>(g) + 1] = kInf;
      for (int k = 0; k < g; ++k) {
        if (!(l[static_cast<std::size_t>(k)] < l[static_cast<std::size_t>(k) + 1])) {
          grid_.lines_ = {};
          return false;
        }
      }
      grid_.count_[j] = g;
      grid_.lo_[j] = lo_[j];
      grid_.inv_[j] = g / extent_[j];
      axes_[j] = Axis{&grid_.lines_[j], lo_[j], grid_.inv_[j], g};
    }
    return true;
  }

  // The points in buckets: one per cell, plus a layer below and above every axis (bucket index
  // cell + 1, from 0 to count + 1), in bucket order, one array per axis. Here: each point's
  // bucket, and per bucket its count (start_[b + 1]).
  void BucketPoints() {
    bucket_total_ = 1;
    for (std::size_t j = 0; j < kD; ++j) {
      buckets_[j] = static_cast<std::size_t>(count_[j]) + 2;
      bucket_total_ *= buckets_[j];
    }
    bucket_of_.resize(n_);
    start_.assign(bucket_total_ + 1, 0);
    for (std::size_t i = 0; i < n_; ++i) {
      std::size_t b = 0;
      for (std::size_t j = 0; j < kD; ++j) {
        b = b * buckets_[j] + static_cast<std::size_t>(axes_[j].Cell(scaled_[i * kD + j]) + 1);
      }
      bucket_of_[i] = static_cast<std::uint32_t>(b);
      ++start_[b + 1];
    }
  }

  // Prefix counts over the buckets: points with bucket index < i on every axis, for (count + 3)^D
  // corners i, so that "no point in this box of buckets" costs 2^D lookups.
  void CountPrefixes() {
    std::size_t corner_total = 1;
    for (std::size_t j = 0; j < kD; ++j) {
      corners_[j] = buckets_[j] + 1;
      corner_total *= corners_[j];
    }
    prefix_.assign(corner_total, 0);
    Index idx{};
    for (std::size_t b = 0; b < bucket_total_; ++b) {
      Unflatten(b, buckets_, idx);
      std::size_t c = 0;
      for (std::size_t j = 0; j < kD; ++j) c = c * corners_[j] + idx[j] + 1;
      prefix_[c] = start_[b + 1];
    }
    // Running sums along each axis in turn.
    std::size_t stride = 1;
    for (std::size_t j = kD; j-- > 0;) {
      for (std::size_t c = 0; c < corner_total; ++c) {
        if ((c / stride) % corners_[j] != 0) prefix_[c] += prefix_[c - stride];
      }
      stride *= corners_[j];
    }
  }

  // The points' coordinates and ranks in bucket order; start_[b] becomes bucket b's first.
  void SortIntoBuckets() {
    for (std::size_t b = 0; b < bucket_total_; ++b) start_[b + 1] += start_[b];
    for (auto& a : bx_) a.resize(n_);
    brank_.resize(n_);
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n_; ++i) {
      const std::uint32_t at = fill[bucket_of_[i]]++;
      for (std::size_t j = 0; j < kD; ++j) bx_[j][at] = scaled_[i * kD + j];
      brank_[at] = static_cast<std::uint32_t>(i);
    }
  }

  // Points in buckets [a_j, c_j] (inclusive) on every axis.
  std::int64_t PointsIn(const Index& a, const Index& c) const {
    std::int64_t total = 0;
    for (unsigned m = 0; m < (1u << D); ++m) {
      std::size_t at = 0;
      int sign = 1;
      for (std::size_t j = 0; j < kD; ++j) {
        const bool upper = ((m >> j) & 1u) == 0;
        at = at * corners_[j] + (upper ? c[j] + 1 : a[j]);
        if (!upper) sign = -sign;
      }
      total += sign * static_cast<std::int64_t>(prefix_[at]);
    }
    return total;
  }

  // The buckets of orthant o of grid vertex `v` (per-axis vertex indices).
  void OrthantBuckets(const Index& v, unsigned o, Index& a, Index& c) const {
    for (std::size_t j = 0; j < kD; ++j) {
      if ((o >> j) & 1u) {
        a[j] = v[j] + 1;
        c[j] = buckets_[j] - 1;
      } else {
        a[j] = 0;
        c[j] = v[j];
      }
    }
  }

  // Per grid vertex v (0 … count on every axis): bit o set when orthant o of the vertex holds a
  // point: + on axis j is cell >= v_j (bucket >= v_j + 1), − is cell < v_j (bucket <= v_j).
  void MarkOccupiedOrthants() {
    vertex_total_ = 1;
    for (std::size_t j = 0; j < kD; ++j) {
      vertices_[j] = static_cast<std::size_t>(count_[j]) + 1;
      vertex_total_ *= vertices_[j];
    }
    occupied_.assign(vertex_total_, 0);
    Index v{}, a{}, c{};
    for (std::size_t at = 0; at < vertex_total_; ++at) {
      Unflatten(at, vertices_, v);
      unsigned mask = 0;
      for (unsigned o = 0; o < kOrthants; ++o) {
        OrthantBuckets(v, o, a, c);
        if (PointsIn(a, c) > 0) mask |= 1u << o;
      }
      occupied_[at] = static_cast<std::uint16_t>(mask);
    }
  }

  // The tree's winners at every grid vertex (the witnesses' source), and where each point sits
  // in bucket order.
  void FindVertexWinners() {
    stamp_.assign(n_, 0);
    bucket_at_.resize(n_);
    for (std::uint32_t i = 0; i < n_; ++i) bucket_at_[brank_[i]] = i;
    vertex_winner_.assign(vertex_total_ * kOrthants, kNoPoint);
    Index v{};
    std::array<double, kD> p{};
    OrthantWinners winners;
    for (std::size_t at = 0; at < vertex_total_; ++at) {
      Unflatten(at, vertices_, v);
      for (std::size_t j = 0; j < kD; ++j) p[j] = grid_.lines_[j][v[j]];
      search_(p.data(), winners);
      for (unsigned o = 0; o < kOrthants; ++o) vertex_winner_[at * kOrthants + o] = winners.rank[o];
    }
  }

  // One cell's list, or the reason it keeps none (unlisted_).
  void ListCell(std::size_t cell) {
    CellWork w;
    LocateCell(cell, w);
    if (!FindNeededOrthants(w) || !FindWitnesses(w)) {
      ++grid_.unlisted_[0];
      return;
    }
    if (!GrowBoundsWithinReach(w)) {
      ++grid_.unlisted_[1];
      return;
    }
    if (!PickCandidates(cell, w)) {
      ++grid_.unlisted_[2];
      return;
    }
    WriteList(cell, w.need);
  }

  void LocateCell(std::size_t cell, CellWork& w) const {
    for (std::size_t j = kD; j-- > 0;) {
      w.k[j] = cell % static_cast<std::size_t>(count_[j]);
      cell /= static_cast<std::size_t>(count_[j]);
    }
    for (std::size_t j = 0; j < kD; ++j) {
      w.cl[j] = grid_.lines_[j][w.k[j]];
      w.ch[j] = grid_.lines_[j][w.k[j] + 1];
      w.widest = std::max(w.widest, w.ch[j] - w.cl[j]);
    }
  }

  // Which orthants need candidates. An orthant empty at the near corner but not at the far one
  // (a hole or an edge of the data) has no bounding point: if few points can lie in it for some
  // query of the cell (those in the far corner's orthant), all of them are its candidates
  // ("whole"); otherwise (a hole: false) the cell keeps no list.
  bool FindNeededOrthants(CellWork& w) const {
    for (unsigned o = 0; o < kOrthants; ++o) {
      std::size_t near = 0, far = 0;
      for (std::size_t j = 0; j < kD; ++j) {
        const std::size_t plus = (o >> j) & 1u;
        near = near * vertices_[j] + w.k[j] + plus;
        far = far * vertices_[j] + w.k[j] + 1 - plus;
        w.far_vertex[o][j] = w.k[j] + 1 - plus;
      }
      if (((occupied_[far] >> o) & 1u) == 0) continue;  // empty for every query of the cell
      w.need |= 1u << o;
      if (((occupied_[near] >> o) & 1u) != 0) continue;
      Index a{}, c{};
      OrthantBuckets(w.far_vertex[o], o, a, c);
      if (PointsIn(a, c) > static_cast<std::int64_t>(options_.max_list / 2)) return false;
      w.whole |= 1u << o;
    }
    return true;
  }

  static void AddWitness(CellWork& w, unsigned o, std::uint32_t i, double d2) {
    int worst = 0;
    for (int k = 0; k < w.witnesses[o]; ++k) {
      if (w.witness[o][k] == i) return;  // met again by a wider pass
      if (w.witness_d2[o][k] > w.witness_d2[o][worst]) worst = k;
    }
    if (w.witnesses[o] < kWitnesses) {
      worst = w.witnesses[o]++;
    } else if (!(d2 < w.witness_d2[o][worst])) {
      return;
    }
    w.witness[o][worst] = i;
    w.witness_d2[o][worst] = d2;
  }

  // The witnesses and bounds: the tree's winner of o at the near corner, and at the vertices one
  // step farther in o's direction on each axis (their orthant o lies inside the near corner's).
  // False when an orthant the counts say is occupied at the near corner got no witness.
  bool FindWitnesses(CellWork& w) const {
    for (unsigned rest = w.need & ~w.whole; rest != 0; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      Index v{};
      for (std::size_t j = 0; j < kD; ++j) v[j] = w.k[j] + ((o >> j) & 1u);
      for (std::size_t step = 0; step <= kD; ++step) {
        Index u = v;
        if (step < kD) {
          if ((o >> step) & 1u) {
            if (u[step] + 1 >= vertices_[step]) continue;
            ++u[step];
          } else {
            if (u[step] == 0) continue;
            --u[step];
          }
        }
        std::size_t at = 0;
        for (std::size_t j = 0; j < kD; ++j) at = at * vertices_[j] + u[j];
        const std::uint32_t r = vertex_winner_[at * kOrthants + o];
        if (r == kNoPoint) continue;
        const std::uint32_t i = bucket_at_[r];
        double d2 = 0.0;
        for (std::size_t j = 0; j < kD; ++j) {
          const double f = ((o >> j) & 1u) ? w.cl[j] : w.ch[j];
          d2 += RoundedSquare(bx_[j][i] - f);
        }
        w.bound[o] = std::min(w.bound[o], d2);
        AddWitness(w, o, i, d2);
      }
      if (w.witnesses[o] == 0) return false;
    }
    return true;
  }

  // Widens the bounds by the rounding margin; false when the widest reaches farther than
  // max_reach cell widths.
  bool GrowBoundsWithinReach(CellWork& w) const {
    double widest_bound = 0.0;
    for (unsigned o = 0; o < kOrthants; ++o) {
      if (((w.need & ~w.whole) >> o) & 1u) {
        w.bound[o] *= kGrow / kShrink;
        widest_bound = std::max(widest_bound, w.bound[o]);
      }
    }
    const double reach = std::sqrt(widest_bound) * (1.0 + 1e-6);
    return reach <= options_.max_reach * w.widest;
  }

  // False when, for every query of the cell, point i is farther than some witness of o: then
  // it never wins o. |q − p|² − |q − w|² is linear in q, so its least value over the cell is at
  // the corner chosen axis by axis; the margin (relative to |f − w|², which bounds both terms
  // wherever it matters) covers the rounding of both sums.
  bool MayBeatWitnesses(const CellWork& w, std::uint32_t i, unsigned o) const {
    for (int k = 0; k < w.witnesses[o]; ++k) {
      const std::uint32_t at = w.witness[o][k];
      double dp = 0.0, dw = 0.0;
      for (std::size_t j = 0; j < kD; ++j) {
        const double x = bx_[j][i], y = bx_[j][at];
        const double corner = x > y ? w.ch[j] : w.cl[j];
        dp += RoundedSquare(corner - x);
        dw += RoundedSquare(corner - y);
      }
      if (dp > dw + 1e-9 * w.witness_d2[o][k]) return false;
    }
    return true;
  }

  // Visits every bucketed point in buckets [a_j, c_j] (inclusive) on every axis, until `visit`
  // returns false.
  template <typename Visit>
  void ForBuckets(const Index& a, const Index& c, Visit&& visit) const {
    // The last axis's buckets are contiguous.
    Index idx = a;
    for (;;) {
      std::size_t row = 0;
      for (std::size_t j = 0; j + 1 < kD; ++j) row = row * buckets_[j] + idx[j];
      row *= buckets_[kD - 1];
      const std::uint32_t from = start_[row + a[kD - 1]];
      const std::uint32_t to = start_[row + c[kD - 1] + 1];
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
  }

  // Point i (bucket order), met for the first time by this cell (stamp `stamp_of`), becomes a
  // candidate when it can lie in a needed orthant o for some query of the cell and is within o's
  // bound of the cell (and may beat o's witnesses), or o is whole. False once the list is too
  // long.
  bool Consider(const CellWork& w, std::uint32_t stamp_of, std::uint32_t i) {
    if (stamp_[i] == stamp_of) return true;
    stamp_[i] = stamp_of;
    double gap2 = 0.0;
    unsigned lt = 0, ge = 0;
    for (std::size_t j = 0; j < kD; ++j) {
      const double x = bx_[j][i];
      const double gap = x < w.cl[j] ? w.cl[j] - x : x > w.ch[j] ? x - w.ch[j] : 0.0;
      gap2 += RoundedSquare(gap);
      lt |= static_cast<unsigned>(x < w.ch[j]) << j;
      ge |= static_cast<unsigned>(x >= w.cl[j]) << j;
    }
    for (unsigned rest = w.need; rest != 0; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      // o is reachable when, on every axis, the point can be on o's side.
      if (((o & ~ge) | (~o & ~lt)) & ((1u << D) - 1u)) continue;
      if (((w.whole >> o) & 1u) != 0 ||
          (gap2 * kShrink <= w.bound[o] && MayBeatWitnesses(w, i, o))) {
        picked_.push_back(Pick{gap2, brank_[i], i});
        break;
      }
    }
    return picked_.size() <= options_.max_list;
  }

  // The candidates into picked_. False when there are more than max_list.
  bool PickCandidates(std::size_t cell, const CellWork& w) {
    picked_.clear();
    bool too_many = false;
    const auto stamp_of = static_cast<std::uint32_t>(cell + 1);
    auto consider = [&](std::uint32_t i) {
      too_many = !Consider(w, stamp_of, i);
      return !too_many;
    };
    // Orthant by orthant: its candidates lie on its sides of the cell, within its own bound.
    for (unsigned rest = w.need & ~w.whole; rest != 0 && !too_many; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      const double r = std::sqrt(w.bound[o]) * (1.0 + 1e-6);
      Index a{}, c{};
      for (std::size_t j = 0; j < kD; ++j) {
        const bool plus = (o >> j) & 1u;
        a[j] = static_cast<std::size_t>(axes_[j].Cell(plus ? w.cl[j] : w.cl[j] - r) + 1);
        c[j] = static_cast<std::size_t>(axes_[j].Cell(plus ? w.ch[j] + r : w.ch[j]) + 1);
      }
      ForBuckets(a, c, consider);
    }
    for (unsigned rest = w.whole; rest != 0 && !too_many; rest &= rest - 1) {
      const unsigned o = static_cast<unsigned>(__builtin_ctz(rest));
      Index a{}, c{};
      OrthantBuckets(w.far_vertex[o], o, a, c);
      ForBuckets(a, c, consider);
    }
    return !too_many;
  }

  // The cell's list from picked_: nearest to the cell first, so that the scan meets the likely
  // winners early and can stop once the remaining entries are all farther than every needed
  // orthant's best.
  void WriteList(std::size_t cell, unsigned need) {
    std::sort(picked_.begin(), picked_.end(), [](const Pick& a, const Pick& b) {
      return a.gap2 < b.gap2 || (a.gap2 == b.gap2 && a.rank < b.rank);
    });
    // Padded to whole blocks of 8 with copies of the last entry (a copy ties with itself: never
    // better, so it changes nothing).
    const std::size_t padded = (picked_.size() + 7) / 8 * 8;
    grid_.span_[cell] = Span{static_cast<std::uint32_t>(grid_.entry_.size()),
                             static_cast<std::uint32_t>(padded), need};
    for (std::size_t e = 0; e < padded; ++e) {
      const Pick& pick = picked_[std::min(e, picked_.size() - 1)];
      grid_.entry_.push_back(position_of_[pick.rank]);
      // The bound the scan compares with, shrunk so that rounding in the query's distance (a few
      // ulps) cannot make an entry look nearer than its bound says.
      if (e % 8 == 0) grid_.block_gap_.push_back(pick.gap2 * kShrink);
    }
    ++grid_.listed_cells_;
  }

  OrthantGrid& grid_;
  const std::vector<std::uint32_t>& position_of_;
  const Search& search_;
  const Options& options_;
  const std::size_t n_;
  const double* const scaled_;

  std::array<double, kD> lo_{}, hi_{}, extent_{};  // the box
  std::array<int, kD> count_{};                    // cells per axis
  std::array<Axis, kD> axes_{};
  Index buckets_{};  // per axis: count + 2
  std::size_t bucket_total_ = 0;
  std::vector<std::uint32_t> bucket_of_;    // per point
  std::vector<std::uint32_t> start_;        // per bucket: its first point in bucket order
  Index corners_{};                         // per axis: buckets + 1
  std::vector<std::uint32_t> prefix_;       // per corner: see CountPrefixes
  std::array<std::vector<double>, kD> bx_;  // per axis: the points' coordinates in bucket order
  std::vector<std::uint32_t> brank_;        // per point in bucket order: its rank
  std::vector<std::uint32_t> bucket_at_;    // per rank: its place in bucket order
  Index vertices_{};                        // per axis: count + 1
  std::size_t vertex_total_ = 0;
  std::vector<std::uint16_t> occupied_;       // per vertex: bit o when orthant o holds a point
  std::vector<std::uint32_t> vertex_winner_;  // per vertex and orthant: the tree's winner
  std::vector<std::uint32_t> stamp_;          // per point: the last cell (+ 1) that considered it
  std::vector<Pick> picked_;                  // the candidates of the cell being listed
};

OrthantGrid::OrthantGrid(const PointCloud& cloud, const std::vector<std::uint32_t>& position_of,
                         const Search& search, const Options& options)
    : dims_(cloud.dims) {
  if (cloud.size() == 0 || cloud.size() > options.max_points || position_of.size() < cloud.size()) {
    return;
  }
  // 3D only: in 4D, with 16 orthants, few cells of the benchmarks' sets kept a list short enough
  // (0.3 % of the queries answered, 0.45 s to build for 4,000 points), so the tree answers.
  if (dims_ == 3) Builder<3>(*this, cloud, position_of, search, options).Run();
}

std::size_t OrthantGrid::bytes() const {
  std::size_t total = span_.capacity() * sizeof(Span) + entry_.capacity() * sizeof(std::uint32_t) +
                      block_gap_.capacity() * sizeof(double);
  for (std::size_t j = 0; j < 4; ++j) total += lines_[j].capacity() * sizeof(double);
  return total;
}

}  // namespace brdf::interp
