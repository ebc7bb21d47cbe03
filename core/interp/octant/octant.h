// The paper's octant method (Sun & Wang, "Interpolation"), made exact by
// docs/interpolation.md ("Making it a function"): around the query P, the nearest sample in each of
// the 2^dims orthants cut by the axis planes through P; the first simplex of the cube of winners
// (3D: ABCF, ACDH, AEFH, CFGH, ACFH; 4D: the 24 Kuhn simplices) that encloses P; the vertex
// spectra blended with P's barycentric weights. Everything happens in the scaled space of
// Options.axis_scale, over the samples plus their symmetry copies (search/point_cloud.h).
//
// Two implementations give bit-identical answers (same vertices, weights, statuses, spectra):
//   OctantInterpolator (MakeOctantInterpolator): the nearest point per orthant from a k-d tree
//                                    (search/kd_tree.h); what MakeInterpolator(Method::kOctant)
//                                    returns.
//   MakeOctantReferenceInterpolator: the paper's O(N) scan (octant/reference.h), for tests and
//                                    `brdf-interp --method octant-reference`.
//
// Not a property of the method: exactness at the data points. When P is a sample, that sample
// wins the (+,+,+) orthant, but an earlier tetrahedron without it can still enclose P (about a
// quarter of the time on uniform random data); then the answer blends its neighbours. On a regular
// lattice the answer at a lattice point is exact.
//
// A query with the wrong number of coordinates or a non-finite one is answered kEmptyOctant
// (no orthant of it holds a sample), with a detail that says so.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "core/interp/interpolator.h"
#include "core/status.h"

namespace brdf::interp {

// One answer of the octant method as numbers only: what EvaluateInto returns without allocating.
struct OctantResult {
  InterpStatus status = InterpStatus::kEmptyOctant;
  int vertex_count = 0;  // kOk: dims + 1 (the simplex's vertices); 0 otherwise
  // kOk: the vertices' SampleSet indices and barycentric weights, in the simplex's order (the same
  // as Evaluate's vertices).
  std::array<std::size_t, 5> index{};
  std::array<double, 5> weight{};
  int simplex = -1;  // kOk: which simplex enclosed the query (SimplexName(simplex, dims))
  // kEmptyOctant: bit o set for every empty orthant (OrthantName(o, dims)); all bits for an
  // invalid query (wrong number of coordinates, or one that is not finite).
  std::uint32_t empty_orthants = 0;
};

// The indexed octant method (k-d tree). Evaluate gives the full answer with provenance; the two
// fast paths give the same numbers without allocating, for batches and grids.
//
// Growing sets (readings landing during a session): Extend makes the interpolator of a grown set
// from an existing one without rebuilding the tree. The tree is shared (immutable, held by every
// interpolator extended from it); the samples it does not hold, the "tail", are scanned one by one
// after the tree search and compete with its winner per orthant on exact squared distance, then on
// rank in the grown set's cloud, so every answer is bit for bit the one Create would give on the
// grown set. A tail longer than the bound is folded into a fresh tree (amortised). Only this
// method grows this way: Delaunay and nearest neighbour are rebuilt by MakeInterpolator.
class OctantInterpolator final : public Interpolator {
 public:
  // How the nearest point per orthant is searched. kGridThenTree adds the tree's grid shortcut
  // (search/orthant_grid.h: 3D clouds of at most 16,384 points; the others get the tree alone):
  // about twice the search speed on the rig grid, for a build of tens of milliseconds instead of
  // about one. Same answers either way. Extend's folds build kTree: they happen while a session
  // records, on the query path, and the set keeps changing.
  enum class Search { kTree, kGridThenTree };

  // Errors (kInvalidArgument): null or empty samples, not 3D/4D, bad options (ValidateOptions).
  static Result<std::unique_ptr<OctantInterpolator>> Create(
      std::shared_ptr<const SampleSet> samples, const Options& options = {},
      Search search = Search::kGridThenTree);

  // The interpolator for `grown`, a set that holds base's samples first, in the same order, then
  // new ones (SampleSet copies grown by Add are). Same options as base. Costs O(tail) (copies the
  // tail's images, shares the tree) while the tail stays within `max_tail` samples (0: the
  // default, DefaultMaxTail); beyond that it builds a fresh tree over all of `grown`
  // (tail_size() == 0 afterwards), as Create(grown, options, Search::kTree) would. `base` is not
  // changed and stays valid.
  // Errors (kInvalidArgument): null `grown`; dims or bands that differ from base's; fewer samples
  // than base; a last base sample (id or coordinates) that differs in `grown`.
  static Result<std::unique_ptr<OctantInterpolator>> Extend(const OctantInterpolator& base,
                                                            std::shared_ptr<const SampleSet> grown,
                                                            std::size_t max_tail = 0);
  // The default tail bound for a tree over `indexed` samples: max(32, indexed / 256). Every query
  // scans the tail (times the symmetry images) after the tree: at 50,000 samples a tail of 769
  // halved the query rate, one of 195 costs far less; a fold (a full build) every 1/256 of the
  // set keeps the amortised build cost per reading at a few hundred samples' worth.
  static std::size_t DefaultMaxTail(std::size_t indexed);
  ~OctantInterpolator() override;

  Method method() const override { return Method::kOctant; }
  int dims() const override;
  int bands() const;
  // The search the index uses: kGridThenTree only when it was asked for and the cloud got a grid
  // (see Search); an interpolator from Extend uses its base's.
  Search search() const;
  const Options& options() const;
  // Samples in the search tree, and samples after them scanned one by one (size = the sum).
  std::size_t indexed_size() const;
  std::size_t tail_size() const;

  Interpolation Evaluate(std::span<const double> query) const override;
  std::size_t HeapBytes() const override;
  InterpStatus SpectrumAt(std::span<const double> query, std::span<double> spectrum) const override;
  // Same answers as SpectrumAt, query by query, bit for bit. Pipelined: while one query's vertex
  // spectra are on their way from memory, the next query is searched. A 3D batch large enough
  // that its queries meet in cells (a quarter of a query per cell or more: about 2,000 queries on
  // the rig grid, 6,000 on 50,000 points) is sorted by cell first: the queries of a grid cell
  // share one scan of its list, and without a grid, consecutive queries search the same part of
  // the tree (octant/octant.cc, SpectraByCell).
  void SpectraAt(std::span<const double> queries, std::span<InterpStatus> statuses,
                 std::span<double> spectra) const override;
  // Evaluate's answers, bit for bit, in query order; a 3D batch of 65,536 queries or a remainder
  // large enough to sort (as for SpectraAt) is sorted and searched by cell first, its answers
  // then assembled in query order (octant/octant.cc). What brdfd's InterpolateBatch calls.
  void EvaluateEach(std::span<const double> queries, const TakeAnswer& take) const override;
  // Queries answered so far by the cell-sorted passes of SpectraAt and EvaluateEach, over this
  // interpolator's life (relaxed counter): how tests tell that a product path takes them.
  std::uint64_t sorted_queries() const;
  // Status, vertices and weights; the blended spectrum goes into `spectrum` when kOk (its first
  // bands() values; a shorter buffer gets the first bands only), untouched otherwise. Same numbers
  // as Evaluate, bit for bit. Thread-safe.
  OctantResult EvaluateInto(std::span<const double> query, std::span<double> spectrum) const;

 private:
  struct Impl;
  explicit OctantInterpolator(std::unique_ptr<const Impl> impl);
  std::unique_ptr<const Impl> impl_;
};

// Errors (kInvalidArgument): null or empty samples, not 3D/4D, bad options (ValidateOptions).
Result<std::unique_ptr<Interpolator>> MakeOctantInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options = {});

}  // namespace brdf::interp
