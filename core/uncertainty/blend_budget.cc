#include "core/uncertainty/blend_budget.h"

#include <map>
#include <mutex>
#include <utility>

namespace brdf::uncertainty {

std::uint32_t NameCode(std::string_view name) {
  static std::mutex mutex;
  static std::map<std::string, std::uint32_t, std::less<>> codes;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto found = codes.find(name);
  if (found != codes.end()) return found->second;
  const auto code = static_cast<std::uint32_t>(codes.size());
  codes.emplace(std::string(name), code);
  return code;
}

Result<BlendBudget> ToBlendBudget(const ReadingBudget& budget,
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
    out.keys.push_back({NameCode(c.name), c.shared.kind, c.shared.id});
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

}  // namespace brdf::uncertainty
