// The uncertainty of a blended value y = Σ wᵢ fᵢ (an interpolated spectrum) from the budgets of
// the readings it blends, after the GUM §5.2 (docs/uncertainty.md, "Interpolated values"):
//   - components shared through the same thing (same name, same sharing, same id: the session's
//     white standard, one reference reading, one dark, the instrument) add linearly, Σ wᵢ uⱼ,ᵢ,
//     before squaring, because they are one error seen by every vertex;
//   - independent components add in quadrature, Σ (wᵢ uⱼ,ᵢ)².
// A reading blended twice (a mirrored or reciprocal copy keeps its reading's id) is one reading:
// its weights are summed first, so its own independent terms correlate with themselves.
// Vertices without a budget are left out and named in not_estimated, never counted as zero.
//
// Apart from it, the interpolation term: how far the blend may be from the sample's true value
// between the readings, estimated from the vertices' own spectra (InterpolationSpread).
// Pure: no I/O.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"
#include "core/uncertainty/blend_budget.h"
#include "core/uncertainty/budget.h"

namespace brdf::uncertainty {

// One blended reading, its budget in the blend's form (blend_budget.h: ToBlendBudget, once per
// reading by whoever keeps the readings: brdfd's index, the grid export's chain).
struct BlendVertex {
  std::int64_t reading_id = 0;
  double weight = 0;                    // its barycentric weight (finite)
  const BlendBudget* budget = nullptr;  // null: the reading has no budget (not estimated)
};

// The measurement uncertainty of a blend, per band (standard uncertainties, k = 1).
struct BlendedUncertainty {
  // sqrt(shared² + independent²): the blend's uncertainty from its vertices' budgets.
  std::vector<double> measurement;
  // The part of `measurement` from shared components (white standard, references, darks,
  // instrument): what averaging more readings of the session would not reduce.
  std::vector<double> shared;
  // What is left out: "reading N: no uncertainty budget (not estimated)" for each vertex without
  // one, and each vertex's own not_estimated entries (each once).
  std::vector<std::string> not_estimated;
};

// The blend's measurement uncertainty over `bands` bands. The shared contributions are read as
// the floats BlendBudget holds, widened to double, and summed in double; so the result is the
// blend of the ReadingBudgets they were made from up to a float's rounding of each shared
// contribution (relative 2⁻²⁴; the independent parts are the budgets' doubles). Errors
// (kInvalidArgument, naming the reading): a non-finite weight, a budget whose bands are not
// `bands`, bands < 1. No vertex with a budget gives zeros with every vertex named as not
// estimated.
Result<BlendedUncertainty> BlendMeasurementUncertainty(std::span<const BlendVertex> vertices,
                                                       int bands);
// The same into *out, its contents replaced and its storage reused: a caller blending many
// answers (a batch, a grid) allocates nothing for the spectra once *out has grown. With
// `with_shared` false, out->shared is left empty (a caller that does not hand it on saves its
// square roots; measurement is the same). On an error *out is left unspecified.
Status BlendMeasurementUncertainty(std::span<const BlendVertex> vertices, int bands,
                                   BlendedUncertainty* out, bool with_shared = true);

// The interpolation term per band: the vertices' weighted spread about the blend,
//   u_int(λ) = sqrt( Σᵢ |wᵢ| (fᵢ(λ) − y(λ))² / Σᵢ |wᵢ| ),
// where fᵢ is vertex i's spectrum and y the blend. Zero at a reading (one vertex of weight 1) and
// wherever the vertices agree; it grows with the change of the BRDF across the cell (docs: its
// limits). `spectra[i]` and `blend` have the same number of bands; weights.size() ==
// spectra.size() ≥ 1 (the caller checks).
std::vector<double> InterpolationSpread(std::span<const double> weights,
                                        std::span<const std::span<const double>> spectra,
                                        std::span<const double> blend);
// The same into *out (blend.size() values, its storage reused).
void InterpolationSpread(std::span<const double> weights,
                         std::span<const std::span<const double>> spectra,
                         std::span<const double> blend, std::vector<double>* out);

}  // namespace brdf::uncertainty
