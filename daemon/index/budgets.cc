#include "daemon/index/budgets.h"

#include <utility>
#include <vector>

namespace brdf::daemon {
namespace {

// glibc's bookkeeping per heap allocation, roughly.
constexpr std::size_t kAllocationOverhead = 16;

// One budget as make_shared allocates it (with the control block) and what its members hold;
// its not_estimated list when it is not the previous budget's.
std::size_t BudgetBytes(const uncertainty::BlendBudget& b, bool own_notes) {
  return sizeof(b) + 2 * sizeof(void*) + kAllocationOverhead + uncertainty::HeapBytes(b, own_notes);
}

}  // namespace

void BudgetList::Add(const uncertainty::ReadingBudget* budget) {
  if (budget == nullptr) {
    Append(nullptr);
    return;
  }
  bool own_notes = false;
  Result<uncertainty::BlendBudget> kept = maker_.Make(*budget, &own_notes);
  if (!kept.ok()) {
    Append(nullptr);
    return;
  }
  auto shared = std::make_shared<const uncertainty::BlendBudget>(std::move(kept).value());
  bytes_ += BudgetBytes(*shared, own_notes);
  Append(std::move(shared));
}

void BudgetList::Append(std::shared_ptr<const uncertainty::BlendBudget> budget) {
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
  chunks_.back()->push_back(std::move(budget));
  ++size_;
}

}  // namespace brdf::daemon
