// The paper's octant method (Sun & Wang, "Interpolation"), made exact by
// ../../../shared/reference/interpolation.md: around the query P, the nearest sample in each of
// the 2^dims orthants cut by the axis planes through P; the first simplex of the cube of winners
// (3D: ABCF, ACDH, AEFH, CFGH, ACFH; 4D: the 24 Kuhn simplices) that encloses P; the vertex
// spectra blended with P's barycentric weights. Everything happens in the scaled space of
// Options.axis_scale, over the samples plus their symmetry copies (point_cloud.h).
//
// Two implementations give bit-identical answers (same vertices, weights, statuses, spectra):
//   OctantInterpolator (MakeOctantInterpolator): the nearest point per orthant from a k-d tree
//                                    (kd_tree.h); what MakeInterpolator(Method::kOctant) returns.
//   MakeOctantReferenceInterpolator: the paper's O(N) scan (octant_reference.h), for tests and
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
class OctantInterpolator final : public Interpolator {
 public:
  // Errors (kInvalidArgument): null or empty samples, not 3D/4D, bad options (ValidateOptions).
  static Result<std::unique_ptr<OctantInterpolator>> Create(
      std::shared_ptr<const SampleSet> samples, const Options& options = {});
  ~OctantInterpolator() override;

  Method method() const override { return Method::kOctant; }
  int dims() const override;
  int bands() const;

  Interpolation Evaluate(std::span<const double> query) const override;
  InterpStatus SpectrumAt(std::span<const double> query, std::span<double> spectrum) const override;
  // Pipelined: while one query's vertex spectra are on their way from memory, the next query is
  // searched. Same answers as SpectrumAt, query by query.
  void SpectraAt(std::span<const double> queries, std::span<InterpStatus> statuses,
                 std::span<double> spectra) const override;
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
