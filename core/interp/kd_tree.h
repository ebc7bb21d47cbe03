// The search index of the fast octant and nearest-neighbour methods: a k-d tree over a
// PointCloud's scaled coordinates. One traversal finds the nearest point in every orthant around
// the query at once (the octant method's step 2) — best-first into the nearer child, pruning a
// subtree only when, for every orthant its box reaches, its lower-bound distance already exceeds
// that orthant's best. The bounds are computed with the same rounded operations as the distances
// (monotone, so never above the computed distance of a point in the box) and then shrunk by a
// relative 1e-12, so pruning can never drop a point that the brute-force scan would pick: results,
// ties included, are identical to the O(N) scan of octant_reference.h. Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/interp/octant_cube.h"
#include "core/interp/point_cloud.h"

namespace brdf::interp {

class KdTree {
 public:
  // Copies the cloud's scaled points (3D or 4D, at least one) into tree order.
  explicit KdTree(const PointCloud& cloud);

  int dims() const { return dims_; }

  // For every orthant o around p (scaled space, OrthantOf numbering): the rank of the point nearest
  // to p in o, the lowest rank among points at the same distance, or kNoPoint when o holds no
  // point; and a pointer to its coordinates in the tree's copy. p must be finite.
  void NearestPerOrthant(const double* p, OrthantWinners& winners) const;

  // The rank of the point nearest to p (the lowest rank among equals). p must be finite.
  std::uint32_t Nearest(const double* p) const;

 private:
  struct Node {
    std::array<double, 4> lo;  // tight bounding box of the node's points
    std::array<double, 4> hi;
    std::uint32_t begin;  // the node's points: positions [begin, end) in tree order
    std::uint32_t end;
    std::uint32_t right;  // right child (left child is the next node); 0 for a leaf
    std::uint32_t axis;   // split axis
    double split;         // points left have coordinate <= split, right >= split
  };
  struct OrthantBest;
  struct NearestBest;

  std::uint32_t Build(std::vector<std::uint32_t>& order, std::uint32_t begin, std::uint32_t end,
                      const PointCloud& cloud);
  template <int D>
  void VisitOrthants(std::uint32_t node, const double* p, OrthantBest& best) const;
  template <int D>
  void VisitNearest(std::uint32_t node, const double* p, NearestBest& best) const;

  int dims_;
  std::vector<Node> nodes_;
  std::vector<double> points_;       // tree order, dims_ per point (scaled)
  std::vector<std::uint32_t> rank_;  // tree position → rank in the cloud
};

}  // namespace brdf::interp
