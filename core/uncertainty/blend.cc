#include "core/uncertainty/blend.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/uncertainty/band_sums.h"

namespace brdf::uncertainty {
namespace {

// One reading of the blend, its weights summed over its copies.
struct Blended {
  std::int64_t reading_id = 0;
  double weight = 0;
  const ReadingBudget* budget = nullptr;
};

// A shared input (name, sharing, id); its Σ wᵢ uⱼ,ᵢ per band is its row of the sums.
struct SharedInput {
  const std::string* name = nullptr;
  SharedThrough through;
};

// What one blend works in, kept by each thread from one blend to the next (a batch blends
// thousands): after the first few, a blend allocates only its result.
struct Scratch {
  std::vector<Blended> readings;
  std::vector<double> independent;  // Σ wᵢ² u_ind,ᵢ² per band
  std::vector<SharedInput> inputs;  // the shared inputs met so far
  std::vector<double> sums;         // inputs.size() rows of `bands` values
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

void AddNotEstimated(std::vector<std::string>& list, const std::string& entry) {
  if (std::find(list.begin(), list.end(), entry) == list.end()) list.push_back(entry);
}

// The row of `sums` that holds the shared input `c` is shared through, added (zeros) when it is
// the first component met of that input.
std::span<double> RowOf(const Component& c, Scratch& s, std::size_t bands) {
  auto input = std::find_if(s.inputs.begin(), s.inputs.end(), [&](const SharedInput& in) {
    return in.through == c.shared && *in.name == c.name;
  });
  if (input == s.inputs.end()) {
    s.inputs.push_back(SharedInput{&c.name, c.shared});
    s.sums.resize(s.sums.size() + bands, 0.0);
    input = s.inputs.end() - 1;
  }
  return {s.sums.data() + static_cast<std::size_t>(input - s.inputs.begin()) * bands, bands};
}

// Adds one reading: its independent part (the budget's, sqrt(Σ independent uⱼ²)) squared and
// weighted into `independent`, its shared components linearly into their input's row of `sums`.
void AddReading(const Blended& b, Scratch& s) {
  const std::size_t bands = s.independent.size();
  AddSquaredBands(s.independent, b.budget->independent, b.weight * b.weight);
  for (const Component& c : b.budget->components) {
    if (c.shared.kind == Sharing::kIndependent) continue;
    AddScaledBands(RowOf(c, s, bands), c.contribution, b.weight);
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
                                   BlendedUncertainty* out) {
  if (bands < 1) return InvalidArgument("a blend needs at least one band");
  Scratch& s = ThreadScratch();
  BRDF_RETURN_IF_ERROR(MergeByReading(vertices, s.readings));
  const auto n = static_cast<std::size_t>(bands);
  out->not_estimated.clear();
  s.independent.assign(n, 0.0);
  s.inputs.clear();
  s.sums.clear();
  for (const Blended& b : s.readings) {
    if (b.budget == nullptr) {
      AddNotEstimated(out->not_estimated, "reading " + std::to_string(b.reading_id) +
                                              ": no uncertainty budget (not estimated)");
      continue;
    }
    BRDF_RETURN_IF_ERROR(CheckBands(b, n));
    for (const std::string& entry : b.budget->not_estimated) {
      AddNotEstimated(out->not_estimated, entry);
    }
    AddReading(b, s);
  }
  // shared² = Σ over inputs of their squared sums, row by row; measurement² = shared² +
  // independent²; then both roots.
  out->shared.assign(n, 0.0);
  for (std::size_t row = 0; row < s.inputs.size(); ++row) {
    AddSquaredBands(out->shared, std::span<const double>(s.sums.data() + row * n, n), 1.0);
  }
  out->measurement.assign(out->shared.begin(), out->shared.end());
  AddScaledBands(out->measurement, s.independent, 1.0);
  SqrtBands(out->measurement);
  SqrtBands(out->shared);
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
