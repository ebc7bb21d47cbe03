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

// A shared input: Σ wᵢ uⱼ,ᵢ per band over the vertices that share it.
struct SharedInput {
  const std::string* name = nullptr;
  SharedThrough through;
  std::vector<double> sum;
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
  bool fits = b.budget->combined.size() == bands;
  for (const Component& c : b.budget->components) fits = fits && c.contribution.size() == bands;
  if (fits) return Status::Ok();
  return InvalidArgument("reading " + std::to_string(b.reading_id) +
                         ": its uncertainty budget does not have " + std::to_string(bands) +
                         " bands, the blend's; were the readings measured on another grid?");
}

void AddNotEstimated(std::vector<std::string>& list, const std::string& entry) {
  if (std::find(list.begin(), list.end(), entry) == list.end()) list.push_back(entry);
}

// Adds one reading's weighted components: independent ones squared into `independent`, shared
// ones linearly into their input's sum.
void AddReading(const Blended& b, std::vector<double>& independent,
                std::vector<SharedInput>& inputs) {
  const std::size_t bands = independent.size();
  for (const Component& c : b.budget->components) {
    if (c.shared.kind == Sharing::kIndependent) {
      for (std::size_t k = 0; k < bands; ++k) {
        const double u = b.weight * c.contribution[k];
        independent[k] += u * u;
      }
      continue;
    }
    auto input = std::find_if(inputs.begin(), inputs.end(), [&](const SharedInput& s) {
      return s.through == c.shared && *s.name == c.name;
    });
    if (input == inputs.end()) {
      inputs.push_back(SharedInput{&c.name, c.shared, std::vector<double>(bands, 0.0)});
      input = inputs.end() - 1;
    }
    for (std::size_t k = 0; k < bands; ++k) input->sum[k] += b.weight * c.contribution[k];
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
    AddReading(b, independent, inputs);
  }
  out.shared.assign(n, 0.0);
  out.measurement.assign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    double shared2 = 0;
    for (const SharedInput& s : inputs) shared2 += s.sum[k] * s.sum[k];
    out.shared[k] = std::sqrt(shared2);
    out.measurement[k] = std::sqrt(shared2 + independent[k]);
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
