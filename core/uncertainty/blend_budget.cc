#include "core/uncertainty/blend_budget.h"

#include <algorithm>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace brdf::uncertainty {

std::uint32_t NameCodes::Code(std::string_view name) {
  constexpr auto kKnown = std::size(kSharedComponentNames);
  const auto known =
      std::find(std::begin(kSharedComponentNames), std::end(kSharedComponentNames), name);
  if (known != std::end(kSharedComponentNames)) {
    return static_cast<std::uint32_t>(known - std::begin(kSharedComponentNames));
  }
  auto other = std::find(others_.begin(), others_.end(), name);
  if (other == others_.end()) other = others_.insert(others_.end(), std::string(name));
  return static_cast<std::uint32_t>(kKnown + static_cast<std::size_t>(other - others_.begin()));
}

Result<BlendBudget> ToBlendBudget(const ReadingBudget& budget, NameCodes& codes,
                                  std::shared_ptr<const std::vector<std::string>> notes) {
  BlendBudget out;
  out.bands = budget.combined.size();
  if (budget.independent.size() != out.bands) {
    return InvalidArgument("its independent part has " + std::to_string(budget.independent.size()) +
                           " bands, its combined " + std::to_string(out.bands));
  }
  out.independent = budget.independent;
  for (const Component& c : budget.components) {
    if (c.shared.kind == Sharing::kIndependent) continue;
    if (c.contribution.size() != out.bands) {
      return InvalidArgument("its component " + c.name + " has " +
                             std::to_string(c.contribution.size()) + " bands, its combined " +
                             std::to_string(out.bands));
    }
    out.keys.push_back({codes.Code(c.name), c.shared.kind, c.shared.id});
    out.shared_rows.insert(out.shared_rows.end(), c.contribution.begin(), c.contribution.end());
  }
  out.keys.shrink_to_fit();
  out.shared_rows.shrink_to_fit();
  if (notes == nullptr || *notes != budget.not_estimated) {
    notes = std::make_shared<const std::vector<std::string>>(budget.not_estimated);
  }
  out.not_estimated = std::move(notes);
  return out;
}

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

}  // namespace

std::size_t HeapBytes(const BlendBudget& b, bool count_notes) {
  std::size_t bytes = VectorBytes(b.independent) + VectorBytes(b.keys) + VectorBytes(b.shared_rows);
  if (count_notes && b.not_estimated) {
    bytes += sizeof(*b.not_estimated) + 2 * sizeof(void*) + kAllocationOverhead;
    bytes += VectorBytes(*b.not_estimated);
    for (const std::string& s : *b.not_estimated) bytes += StringBytes(s);
  }
  return bytes;
}

Result<BlendBudget> BlendBudgetMaker::Make(const ReadingBudget& budget, bool* new_notes) {
  Result<BlendBudget> made = ToBlendBudget(budget, codes_, last_notes_);
  if (!made.ok()) return made;
  if (new_notes != nullptr) *new_notes = made->not_estimated != last_notes_;
  last_notes_ = made->not_estimated;
  return made;
}

}  // namespace brdf::uncertainty
