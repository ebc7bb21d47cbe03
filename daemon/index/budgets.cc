#include "daemon/index/budgets.h"

#include <string>
#include <utility>
#include <vector>

namespace brdf::daemon {
namespace {

// glibc's bookkeeping per heap allocation, roughly.
constexpr std::size_t kAllocationOverhead = 16;

template <typename T>
std::size_t VectorBytes(const std::vector<T>& v) {
  return v.capacity() == 0 ? 0 : v.capacity() * sizeof(T) + kAllocationOverhead;
}

// A string's own storage, beyond what fits inside it (the short-string buffer).
std::size_t StringBytes(const std::string& s) {
  static const std::size_t kInline = std::string().capacity();
  return s.capacity() <= kInline ? 0 : s.capacity() + 1 + kAllocationOverhead;
}

// One budget as make_shared allocates it (with the control block) and what its members hold.
std::size_t BudgetBytes(const uncertainty::ReadingBudget& b) {
  std::size_t bytes = sizeof(b) + 2 * sizeof(void*) + kAllocationOverhead;
  bytes += VectorBytes(b.value) + VectorBytes(b.combined) + VectorBytes(b.independent);
  bytes += VectorBytes(b.components) + VectorBytes(b.not_estimated);
  for (const uncertainty::Component& c : b.components) {
    bytes += StringBytes(c.name) + VectorBytes(c.contribution);
  }
  for (const std::string& s : b.not_estimated) bytes += StringBytes(s);
  return bytes;
}

}  // namespace

uncertainty::ReadingBudget BudgetForBlend(const uncertainty::ReadingBudget& budget) {
  uncertainty::ReadingBudget kept;
  kept.quantity = budget.quantity;
  for (const uncertainty::Component& c : budget.components) {
    if (c.shared.kind != uncertainty::Sharing::kIndependent) kept.components.push_back(c);
  }
  kept.components.shrink_to_fit();
  kept.combined = budget.combined;
  kept.independent = budget.independent;
  kept.not_estimated = budget.not_estimated;
  return kept;
}

void BudgetList::Add(std::shared_ptr<const uncertainty::ReadingBudget> budget) {
  if (size_ % kChunk == 0) {
    chunks_.push_back(std::make_shared<Chunk>());
    chunks_.back()->reserve(kChunk);
  } else if (chunks_.back().use_count() > 1) {
    // Shared with a published copy: write into a chunk of our own, never into theirs.
    auto own = std::make_shared<Chunk>();
    own->reserve(kChunk);
    own->assign(chunks_.back()->begin(),
                chunks_.back()->begin() + static_cast<std::ptrdiff_t>(size_ % kChunk));
    chunks_.back() = std::move(own);
  }
  if (size_ % kChunk == 0) bytes_ += kChunk * sizeof(budget) + kAllocationOverhead;
  if (budget) bytes_ += BudgetBytes(*budget);
  chunks_.back()->push_back(std::move(budget));
  ++size_;
}

}  // namespace brdf::daemon
