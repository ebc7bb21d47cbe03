#include "core/uncertainty/blend.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace brdf::uncertainty {
namespace {

// One reading of the blend, its weights summed over its copies.
struct Blended {
  std::int64_t reading_id = 0;
  double weight = 0;
  const ReadingBudget* budget = nullptr;
};

// A shared input (name, sharing, id); its Σ wᵢ uⱼ,ᵢ per band is row `row` of the sums.
struct SharedInput {
  const std::string* name = nullptr;
  SharedThrough through;
};

Result<std::vector<Blended>> MergeByReading(std::span<const BlendVertex> vertices) {
  std::vector<Blended> out;
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
  return out;
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

// row[k] += w · u[k] for k < n (restrict: the compiler keeps w in a register).
void AddScaled(double* __restrict row, const double* __restrict u, double w, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) row[k] += w * u[k];
}

// Adds one reading: its independent part (the budget's, sqrt(Σ independent uⱼ²)) squared and
// weighted into `independent`, its shared components linearly into their input's row of `sums`
// (inputs.size() rows of `bands` values).
void AddReading(const Blended& b, std::vector<double>& independent,
                std::vector<SharedInput>& inputs, std::vector<double>& sums) {
  const std::size_t bands = independent.size();
  const double w = b.weight;
  const double w2 = w * w;
  const double* ind = b.budget->independent.data();
  for (std::size_t k = 0; k < bands; ++k) independent[k] += w2 * ind[k] * ind[k];
  for (const Component& c : b.budget->components) {
    if (c.shared.kind == Sharing::kIndependent) continue;
    auto input = std::find_if(inputs.begin(), inputs.end(), [&](const SharedInput& s) {
      return s.through == c.shared && *s.name == c.name;
    });
    if (input == inputs.end()) {
      inputs.push_back(SharedInput{&c.name, c.shared});
      sums.resize(sums.size() + bands, 0.0);
      input = inputs.end() - 1;
    }
    AddScaled(sums.data() + static_cast<std::size_t>(input - inputs.begin()) * bands,
              c.contribution.data(), w, bands);
  }
}

}  // namespace

Result<BlendedUncertainty> BlendMeasurementUncertainty(std::span<const BlendVertex> vertices,
                                                       int bands) {
  if (bands < 1) return InvalidArgument("a blend needs at least one band");
  BRDF_ASSIGN_OR_RETURN(std::vector<Blended> readings, MergeByReading(vertices));
  const auto n = static_cast<std::size_t>(bands);
  BlendedUncertainty out;
  std::vector<double> independent(n, 0.0);
  std::vector<SharedInput> inputs;
  std::vector<double> sums;
  inputs.reserve(16);
  sums.reserve(16 * n);
  for (const Blended& b : readings) {
    if (b.budget == nullptr) {
      AddNotEstimated(out.not_estimated, "reading " + std::to_string(b.reading_id) +
                                             ": no uncertainty budget (not estimated)");
      continue;
    }
    BRDF_RETURN_IF_ERROR(CheckBands(b, n));
    for (const std::string& entry : b.budget->not_estimated) {
      AddNotEstimated(out.not_estimated, entry);
    }
    AddReading(b, independent, inputs, sums);
  }
  // Σ over inputs of their squared sums, accumulated row by row into `shared2`.
  std::vector<double>& shared2 = out.shared;
  shared2.assign(n, 0.0);
  for (std::size_t row = 0; row < inputs.size(); ++row) {
    const double* sum = sums.data() + row * n;
    for (std::size_t k = 0; k < n; ++k) shared2[k] += sum[k] * sum[k];
  }
  out.measurement.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    out.measurement[k] = std::sqrt(shared2[k] + independent[k]);
    shared2[k] = std::sqrt(shared2[k]);
  }
  return out;
}

std::vector<double> InterpolationSpread(std::span<const double> weights,
                                        std::span<const std::span<const double>> spectra,
                                        std::span<const double> blend) {
  std::vector<double> out(blend.size(), 0.0);
  double total = 0;
  for (double w : weights) total += std::abs(w);
  if (total <= 0) return out;
  for (std::size_t i = 0; i < spectra.size() && i < weights.size(); ++i) {
    const double w = std::abs(weights[i]) / total;
    const std::size_t bands = std::min(blend.size(), spectra[i].size());
    for (std::size_t k = 0; k < bands; ++k) {
      const double d = spectra[i][k] - blend[k];
      out[k] += w * d * d;
    }
  }
  for (double& v : out) v = std::sqrt(v);
  return out;
}

}  // namespace brdf::uncertainty
