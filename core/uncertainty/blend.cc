#include "core/uncertainty/blend.h"

#include <algorithm>
#include <array>
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
  const BlendBudget* budget = nullptr;
};

// A shared input (name, sharing, id: its key) and the vertices' contributions to it with their
// weights: its Σ wᵢ uⱼ,ᵢ per band is formed in one pass when it is squared.
struct SharedInput {
  SharedKey key;
  std::vector<const float*> contributions;
  std::vector<double> weights;
};

// What one blend works in, kept by each thread from one blend to the next (a batch or a grid
// blends thousands): after the first few, a blend allocates nothing here.
struct Scratch {
  std::vector<Blended> readings;
  // Each reading's independent part and its weight², summed squared into the measurement.
  std::vector<const double*> independent;
  std::vector<double> independent_scales;
  // The first `used` are this blend's shared inputs; the rest are kept for their storage.
  std::vector<SharedInput> inputs;
  std::size_t used = 0;
  std::vector<WeightedFloatRows> rows;  // the used inputs as BlendSquaredBands takes them
  std::vector<const std::vector<std::string>*> notes_added;  // lists already in not_estimated
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

std::string NoBudget(std::int64_t reading_id) {
  return "reading " + std::to_string(reading_id) + ": no uncertainty budget (not estimated)";
}

std::string OtherBands(std::int64_t reading_id, std::size_t bands) {
  return "reading " + std::to_string(reading_id) + ": its uncertainty budget does not have " +
         std::to_string(bands) + " bands, the blend's; were the readings measured on another grid?";
}

// The shared input `key` names, added (with no contributions yet) when it is the first met.
// `hint`: where to look first (the readings of a session list their components in the same order,
// so a reading's n-th shared component is most often the n-th input); inputs are unique by key,
// so the one found there is the one a scan would find.
SharedInput& InputOf(const SharedKey& key, std::size_t hint, Scratch& s) {
  if (hint < s.used && s.inputs[hint].key == key) return s.inputs[hint];
  for (std::size_t j = 0; j < s.used; ++j) {
    if (s.inputs[j].key == key) return s.inputs[j];
  }
  if (s.used == s.inputs.size()) s.inputs.emplace_back();
  SharedInput& input = s.inputs[s.used++];
  input.key = key;
  input.contributions.clear();
  input.weights.clear();
  return input;
}

// Adds one reading: its independent part (sqrt(Σ independent uⱼ²), blend_budget.h) to be squared
// with its weight², its shared components' rows to their inputs, with its weight.
void AddReading(const Blended& b, Scratch& s) {
  const BlendBudget& budget = *b.budget;
  s.independent.push_back(budget.independent.data());
  s.independent_scales.push_back(b.weight * b.weight);
  for (std::size_t j = 0; j < budget.keys.size(); ++j) {
    SharedInput& input = InputOf(budget.keys[j], j, s);
    input.contributions.push_back(budget.row(j));
    input.weights.push_back(b.weight);
  }
}

// The reading's not_estimated entries, each once: a list already added (shared by readings with
// the same entries) is skipped whole.
void AddNotes(const BlendBudget& budget, Scratch& s, NoteList& notes) {
  const std::vector<std::string>* list = budget.not_estimated.get();
  if (list == nullptr || list->empty()) return;
  if (std::find(s.notes_added.begin(), s.notes_added.end(), list) != s.notes_added.end()) return;
  s.notes_added.push_back(list);
  for (const std::string& entry : *list) notes.AddUnique(entry);
}

// shared² = Σ over inputs of (Σ wᵢ uⱼ,ᵢ)², measurement² = shared² + independent², in one pass
// over the bands, from the inputs `s` gathered; then the roots.
void SumAndRoot(Scratch& s, std::size_t n, bool with_shared, BlendedUncertainty* out) {
  s.rows.clear();
  for (std::size_t j = 0; j < s.used; ++j) {
    const SharedInput& input = s.inputs[j];
    s.rows.push_back({input.contributions.data(), input.weights.data(), input.weights.size()});
  }
  out->measurement.resize(n);
  out->shared.resize(with_shared ? n : 0);
  BlendSquaredBands(out->measurement, out->shared, s.independent, s.independent_scales, s.rows);
  SqrtBands(out->measurement);
  SqrtBands(out->shared);
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
  s.independent.clear();
  s.independent_scales.clear();
  s.notes_added.clear();
  s.used = 0;
  for (const Blended& b : s.readings) {
    if (b.budget == nullptr) {
      notes.AddUnique(NoBudget(b.reading_id));
      continue;
    }
    if (b.budget->bands != n) return InvalidArgument(OtherBands(b.reading_id, n));
    AddNotes(*b.budget, s, notes);
    AddReading(b, s);
  }
  notes.Finish();
  SumAndRoot(s, n, with_shared, out);
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
  const std::size_t m = std::min(spectra.size(), weights.size());
  // Every vertex on the blend's bands (as always from the API): one pass over the bands.
  constexpr std::size_t kInline = 8;
  bool whole = m <= kInline;
  for (std::size_t i = 0; i < m && whole; ++i) whole = spectra[i].size() >= blend.size();
  if (whole) {
    std::array<const double*, kInline> rows{};
    std::array<double, kInline> scales{};
    for (std::size_t i = 0; i < m; ++i) {
      rows[i] = spectra[i].data();
      scales[i] = std::abs(weights[i]) / total;
    }
    SquaredDifferencesBands(*out, std::span(rows).first(m), blend, std::span(scales).first(m));
  } else {
    for (std::size_t i = 0; i < m; ++i) {
      const std::size_t bands = std::min(blend.size(), spectra[i].size());
      AddSquaredDifferenceBands(std::span<double>(*out).first(bands), spectra[i].first(bands),
                                blend.first(bands), std::abs(weights[i]) / total);
    }
  }
  SqrtBands(*out);
}

}  // namespace brdf::uncertainty
