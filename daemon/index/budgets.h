// BudgetList: the uncertainty budgets of a sample set's readings, position for position (budget
// i is the one of the set's sample i; null: the reading has none, "not estimated"). An
// interpolated value's measurement uncertainty blends its vertices' budgets
// (core/uncertainty/blend.h), found here by the vertex's position in the set.
//
// Shared like interp::SampleSet: storage in chunks of kChunk budgets, a copy shares them and Add
// on a copy writes into a chunk of its own (the last, partly filled one is copied first when
// another list holds it too), so a snapshot's list never changes while later readings are added.
// Not thread-safe for Add; a published list is read-only and may be read by many threads.
//
// The index holds what the blend needs of each budget, in the blend's form
// (core/uncertainty/blend_budget.h: the independent part, the shared contributions as floats,
// integer keys): a paper-grid session's 2,112 whole budgets would be most of its cached memory,
// and a batch's blends read half the bytes.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "core/uncertainty/blend_budget.h"
#include "core/uncertainty/budget.h"

namespace brdf::daemon {

class BudgetList {
 public:
  static constexpr std::size_t kChunk = 128;

  // Appends the next sample's budget in the blend's form (uncertainty::ToBlendBudget, its names
  // coded by the list's own NameCodes, copied with it; its not_estimated list shared with the
  // previous budget's when they hold the same entries). Null,
  // or a budget whose parts do not all have the same number of bands: not estimated.
  void Add(const uncertainty::ReadingBudget* budget);

  std::size_t size() const { return size_; }
  // Sample i's budget, or null when it has none or i is beyond the list.
  const uncertainty::BlendBudget* at(std::size_t i) const {
    return i < size_ ? (*chunks_[i / kChunk])[i % kChunk].get() : nullptr;
  }
  // Heap held by the list and its budgets (for the cache's bound): each budget's allocation, its
  // vectors' and strings' storage with glibc's overhead per allocation, the list's slots.
  std::size_t bytes() const { return bytes_; }

 private:
  using Chunk = std::vector<std::shared_ptr<const uncertainty::BlendBudget>>;
  void Append(std::shared_ptr<const uncertainty::BlendBudget> budget);

  std::vector<std::shared_ptr<Chunk>> chunks_;
  // Its codes of the budgets' shared components' names and the last budget's notes. A copy (the
  // next snapshot's list) codes the names it holds as this one does, so the budgets they share
  // keep their meaning; budgets are blended only with those of the same list.
  uncertainty::BlendBudgetMaker maker_;
  std::size_t size_ = 0;
  std::size_t bytes_ = 0;
};

}  // namespace brdf::daemon
