#include "core/uncertainty/blend.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/uncertainty/band_sums.h"
#include "core/uncertainty/note_list.h"

namespace brdf::uncertainty {
namespace {

// One reading of the blend, its weights summed over its copies.
struct Blended {
  std::int64_t reading_id = 0;
  double weight = 0;
  const ReadingBudget* budget = nullptr;
};

// A shared input (name, sharing, id) and the vertices' contributions to it with their weights:
// its Σ wᵢ uⱼ,ᵢ per band is formed in one pass when it is squared.
struct SharedInput {
  const std::string* name = nullptr;
  SharedThrough through;
  std::vector<const double*> contributions;
  std::vector<double> weights;
};

// What one blend works in, kept by each thread from one blend to the next (a batch blends
// thousands): after the first few, a blend allocates nothing here.
struct Scratch {
  std::vector<Blended> readings;
  std::vector<double> independent;  // Σ wᵢ² u_ind,ᵢ² per band
  // The first `used` are this blend's shared inputs; the rest are kept for their storage.
  std::vector<SharedInput> inputs;
  std::size_t used = 0;
};

Scratch& ThreadScratch() {
  thread_local Scratch scratch;
  return scratch;
}

Status MergeByReading(std::span<const BlendVertex> vertices, std::vector<Blended>& out) {
  out.clear();
  for (const BlendVertex& v : vertices) {
    if (!std::isfinite(v.weight)) {
      return InvalidArgument("reading " + std::to_string(v.reading_id) +
                             ": its blend weight is not a finite number");
    }
    auto same = std::find_if(out.begin(), out.end(),
                             [&](const Blended& b) { return b.reading_id == v.reading_id; });
    if (same == out.end()) {
      out.push_back(Blended{v.reading_id, v.weight, v.budget});
    } else {
      same->weight += v.weight;
      if (same->budget == nullptr) same->budget = v.budget;
    }
  }
  return Status::Ok();
}

Status CheckBands(const Blended& b, std::size_t bands) {
  bool fits = b.budget->combined.size() == bands && b.budget->independent.size() == bands;
  for (const Component& c : b.budget->components) fits = fits && c.contribution.size() == bands;
  if (fits) return Status::Ok();
  return InvalidArgument("reading " + std::to_string(b.reading_id) +
                         ": its uncertainty budget does not have " + std::to_string(bands) +
                         " bands, the blend's; were the readings measured on another grid?");
}

// The shared input `c` is shared through, added (with no contributions yet) when it is the first
// component met of that input.
SharedInput& InputOf(const Component& c, Scratch& s) {
  for (std::size_t j = 0; j < s.used; ++j) {
    if (s.inputs[j].through == c.shared && *s.inputs[j].name == c.name) return s.inputs[j];
  }
  if (s.used == s.inputs.size()) s.inputs.emplace_back();
  SharedInput& input = s.inputs[s.used++];
  input.name = &c.name;
  input.through = c.shared;
  input.contributions.clear();
  input.weights.clear();
  return input;
}

// Adds one reading: its independent part (the budget's, sqrt(Σ independent uⱼ²)) squared and
// weighted into `independent`, its shared components to their inputs, with its weight.
void AddReading(const Blended& b, Scratch& s) {
  AddSquaredBands(s.independent, b.budget->independent, b.weight * b.weight);
  for (const Component& c : b.budget->components) {
    if (c.shared.kind == Sharing::kIndependent) continue;
    SharedInput& input = InputOf(c, s);
    input.contributions.push_back(c.contribution.data());
    input.weights.push_back(b.weight);
  }
}

}  // namespace

Result<BlendedUncertainty> BlendMeasurementUncertainty(std::span<const BlendVertex> vertices,
                                                       int bands) {
  BlendedUncertainty out;
  BRDF_RETURN_IF_ERROR(BlendMeasurementUncertainty(vertices, bands, &out));
  return out;
}

Status BlendMeasurementUncertainty(std::span<const BlendVertex> vertices, int bands,
                                   BlendedUncertainty* out, bool with_shared) {
  if (bands < 1) return InvalidArgument("a blend needs at least one band");
  Scratch& s = ThreadScratch();
  BRDF_RETURN_IF_ERROR(MergeByReading(vertices, s.readings));
  const auto n = static_cast<std::size_t>(bands);
  NoteList notes(out->not_estimated);
  s.independent.assign(n, 0.0);
  s.used = 0;
  for (const Blended& b : s.readings) {
    if (b.budget == nullptr) {
      notes.AddUnique("reading " + std::to_string(b.reading_id) +
                      ": no uncertainty budget (not estimated)");
      continue;
    }
    BRDF_RETURN_IF_ERROR(CheckBands(b, n));
    for (const std::string& entry : b.budget->not_estimated) {
      notes.AddUnique(entry);
    }
    AddReading(b, s);
  }
  notes.Finish();
  // shared² = Σ over inputs of (Σ wᵢ uⱼ,ᵢ)², an input at a time; measurement² = shared² +
  // independent²; then both roots.
  out->shared.assign(n, 0.0);
  for (std::size_t j = 0; j < s.used; ++j) {
    AddSquaredSumBands(out->shared, s.inputs[j].contributions, s.inputs[j].weights);
  }
  out->measurement.assign(out->shared.begin(), out->shared.end());
  AddScaledBands(out->measurement, s.independent, 1.0);
  SqrtBands(out->measurement);
  if (with_shared) {
    SqrtBands(out->shared);
  } else {
    out->shared.clear();
  }
  return Status::Ok();
}

std::vector<double> InterpolationSpread(std::span<const double> weights,
                                        std::span<const std::span<const double>> spectra,
                                        std::span<const double> blend) {
  std::vector<double> out;
  InterpolationSpread(weights, spectra, blend, &out);
  return out;
}

void InterpolationSpread(std::span<const double> weights,
                         std::span<const std::span<const double>> spectra,
                         std::span<const double> blend, std::vector<double>* out) {
  out->assign(blend.size(), 0.0);
  double total = 0;
  for (double w : weights) total += std::abs(w);
  if (total <= 0) return;
  for (std::size_t i = 0; i < spectra.size() && i < weights.size(); ++i) {
    const std::size_t bands = std::min(blend.size(), spectra[i].size());
    AddSquaredDifferenceBands(std::span<double>(*out).first(bands), spectra[i].first(bands),
                              blend.first(bands), std::abs(weights[i]) / total);
  }
  SqrtBands(*out);
}

}  // namespace brdf::uncertainty
