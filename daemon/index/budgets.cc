#include "daemon/index/budgets.h"

#include <utility>

namespace brdf::daemon {
namespace {

std::size_t BudgetBytes(const uncertainty::ReadingBudget& b) {
  std::size_t values = b.value.size() + b.combined.size() + b.independent.size();
  for (const uncertainty::Component& c : b.components) values += c.contribution.size();
  return sizeof(b) + values * sizeof(double) + b.components.size() * sizeof(uncertainty::Component);
}

}  // namespace

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
  if (budget) bytes_ += BudgetBytes(*budget);
  chunks_.back()->push_back(std::move(budget));
  ++size_;
}

}  // namespace brdf::daemon
