#include "core/interp/kd_tree.h"

#include <algorithm>
#include <bit>
#include <limits>
#include <numeric>

namespace brdf::interp {
namespace {

// Points per leaf (a leaf holds kLeafSize/2 … kLeafSize). Scanning a point is much cheaper than
// deciding whether to visit a node (which bounds up to 2^dims orthants), so leaves are large.
constexpr std::uint32_t kLeafSize = 32;

// Lower bounds are shrunk by this factor before pruning. They are already never above the
// computed distance of a point in the box (same rounded operations, monotone); the margin keeps
// that true should a compiler contract the distance into fused multiply-adds.
constexpr double kBoundShrink = 1.0 - 1e-12;

constexpr double kInf = std::numeric_limits<double>::infinity();

inline double Sq(double x) {
  return x * x;
}

// Bit o of PlusMask(j, D) is set when orthant o is on the + side of axis j.
constexpr std::uint32_t PlusMask(int j, int dims) {
  std::uint32_t m = 0;
  for (int o = 0; o < (1 << dims); ++o) {
    if ((o >> j) & 1) m |= 1u << o;
  }
  return m;
}

template <int D>
constexpr std::array<std::uint32_t, D> PlusMasks() {
  std::array<std::uint32_t, D> m{};
  for (int j = 0; j < D; ++j) m[static_cast<std::size_t>(j)] = PlusMask(j, D);
  return m;
}

}  // namespace

struct KdTree::OrthantBest {
  std::array<double, kMaxOrthants> d2;
  std::array<std::uint32_t, kMaxOrthants> rank;
  std::array<std::uint32_t, kMaxOrthants> pos;  // tree position of the best point
  double worst;  // max of d2 over the orthants: a node farther than this cannot help any of them
};

struct KdTree::NearestBest {
  double d2 = kInf;
  std::uint32_t rank = kNoPoint;
};

KdTree::KdTree(const PointCloud& cloud) : dims_(cloud.dims) {
  const auto n = static_cast<std::uint32_t>(cloud.size());
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * (n / kLeafSize) + 2);
  Build(order, 0, n, cloud);
  const auto d = static_cast<std::size_t>(dims_);
  points_.resize(static_cast<std::size_t>(n) * d);
  for (std::size_t pos = 0; pos < n; ++pos) {
    const auto src = cloud.scaled_point(order[pos]);
    std::copy(src.begin(), src.end(), points_.begin() + static_cast<std::ptrdiff_t>(pos * d));
  }
  rank_ = std::move(order);
}

std::uint32_t KdTree::Build(std::vector<std::uint32_t>& order, std::uint32_t begin,
                            std::uint32_t end, const PointCloud& cloud) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node{};
  node.begin = begin;
  node.end = end;
  node.lo.fill(kInf);
  node.hi.fill(-kInf);
  for (std::uint32_t k = begin; k < end; ++k) {
    const auto x = cloud.scaled_point(order[k]);
    for (int j = 0; j < dims_; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      node.lo[uj] = std::min(node.lo[uj], x[uj]);
      node.hi[uj] = std::max(node.hi[uj], x[uj]);
    }
  }
  int axis = 0;
  for (int j = 1; j < dims_; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const auto ua = static_cast<std::size_t>(axis);
    if (node.hi[uj] - node.lo[uj] > node.hi[ua] - node.lo[ua]) axis = j;
  }
  const auto ua = static_cast<std::size_t>(axis);
  // A leaf when small, or when every point is the same (duplicates cannot be split apart).
  if (end - begin <= kLeafSize || !(node.hi[ua] > node.lo[ua])) {
    nodes_[index] = node;
    return index;
  }
  const std::uint32_t mid = begin + (end - begin) / 2;
  const auto d = static_cast<std::size_t>(dims_);
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) {
                     const double ca = cloud.scaled[a * d + ua];
                     const double cb = cloud.scaled[b * d + ua];
                     return ca < cb || (ca == cb && a < b);
                   });
  node.axis = static_cast<std::uint32_t>(axis);
  node.split = cloud.scaled[order[mid] * d + ua];
  nodes_[index] = node;
  Build(order, begin, mid, cloud);
  const std::uint32_t right = Build(order, mid, end, cloud);
  nodes_[index].right = right;
  return index;
}

template <int D>
void KdTree::VisitOrthants(std::uint32_t node_index, const double* p, OrthantBest& best) const {
  static constexpr std::array<std::uint32_t, D> kPlus = PlusMasks<D>();
  static constexpr int kOrthants = 1 << D;
  const Node& node = nodes_[node_index];
  // Which orthants the box reaches, and its distance from p. On an axis where the box lies
  // entirely on one side of p it reaches only that side, so this distance is also the bound for
  // every orthant it reaches (the orthant's part of the box is as far as the whole box).
  std::uint32_t reach = (1u << kOrthants) - 1u;
  double bound = 0.0;
#pragma GCC unroll 4
  for (int j = 0; j < D; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double lo = node.lo[uj], hi = node.hi[uj], q = p[j];
    if (!(lo < q)) reach &= kPlus[uj];    // nothing on the − side
    if (!(hi >= q)) reach &= ~kPlus[uj];  // nothing on the + side
    bound += hi < q ? Sq(hi - q) : (lo > q ? Sq(lo - q) : 0.0);
  }
  bound *= kBoundShrink;
  // Farther than every orthant's best (once all have one): nothing to find here.
  if (bound > best.worst) return;
  bool worth = false;
  for (std::uint32_t m = reach; m != 0; m &= m - 1) {
    if (bound <= best.d2[static_cast<std::size_t>(std::countr_zero(m))]) {
      worth = true;
      break;
    }
  }
  if (!worth) return;

  if (node.right == 0) {
    bool improved = false;
    for (std::uint32_t pos = node.begin; pos < node.end; ++pos) {
      const double* x = points_.data() + static_cast<std::size_t>(pos) * D;
      const auto o = static_cast<std::size_t>(OrthantOf<D>(x, p));
      const double d2 = SquaredDistance<D>(x, p);
      if (d2 < best.d2[o] || (d2 == best.d2[o] && rank_[pos] < best.rank[o])) {
        best.d2[o] = d2;
        best.rank[o] = rank_[pos];
        best.pos[o] = pos;
        improved = true;
      }
    }
    if (improved) {
      double worst = 0.0;
      for (int o = 0; o < kOrthants; ++o)
        worst = std::max(worst, best.d2[static_cast<std::size_t>(o)]);
      best.worst = worst;
    }
    return;
  }
  if (p[node.axis] < node.split) {
    VisitOrthants<D>(node_index + 1, p, best);
    VisitOrthants<D>(node.right, p, best);
  } else {
    VisitOrthants<D>(node.right, p, best);
    VisitOrthants<D>(node_index + 1, p, best);
  }
}

template <int D>
void KdTree::VisitNearest(std::uint32_t node_index, const double* p, NearestBest& best) const {
  const Node& node = nodes_[node_index];
  double bound = 0.0;
#pragma GCC unroll 4
  for (int j = 0; j < D; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double q = p[j];
    bound += q < node.lo[uj] ? Sq(node.lo[uj] - q) : (q > node.hi[uj] ? Sq(q - node.hi[uj]) : 0.0);
  }
  if (!(bound * kBoundShrink <= best.d2)) return;

  if (node.right == 0) {
    for (std::uint32_t pos = node.begin; pos < node.end; ++pos) {
      const double* x = points_.data() + static_cast<std::size_t>(pos) * D;
      const double d2 = SquaredDistance<D>(x, p);
      const std::uint32_t r = rank_[pos];
      if (d2 < best.d2 || (d2 == best.d2 && r < best.rank)) {
        best.d2 = d2;
        best.rank = r;
      }
    }
    return;
  }
  if (p[node.axis] < node.split) {
    VisitNearest<D>(node_index + 1, p, best);
    VisitNearest<D>(node.right, p, best);
  } else {
    VisitNearest<D>(node.right, p, best);
    VisitNearest<D>(node_index + 1, p, best);
  }
}

void KdTree::NearestPerOrthant(const double* p, OrthantWinners& winners) const {
  OrthantBest best;
  best.d2.fill(kInf);
  best.rank.fill(kNoPoint);
  best.pos.fill(0);
  best.worst = kInf;
  if (dims_ == 3) {
    VisitOrthants<3>(0, p, best);
  } else {
    VisitOrthants<4>(0, p, best);
  }
  const std::size_t orthants = std::size_t{1} << dims_;
  const auto d = static_cast<std::size_t>(dims_);
  for (std::size_t o = 0; o < orthants; ++o) {
    winners.rank[o] = best.rank[o];
    winners.scaled[o] = best.rank[o] == kNoPoint
                            ? nullptr
                            : points_.data() + static_cast<std::size_t>(best.pos[o]) * d;
  }
}

std::uint32_t KdTree::Nearest(const double* p) const {
  NearestBest best;
  if (dims_ == 3) {
    VisitNearest<3>(0, p, best);
  } else {
    VisitNearest<4>(0, p, best);
  }
  return best.rank;
}

}  // namespace brdf::interp
