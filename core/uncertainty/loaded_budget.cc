#include "core/uncertainty/loaded_budget.h"

#include <memory>
#include <string>
#include <utility>

namespace brdf::uncertainty {

LoadedBudget LoadBudget(const ReadingBudget& budget, BlendBudgetMaker& maker) {
  LoadedBudget out;
  if (Result<BlendBudget> blend = maker.Make(budget); blend.ok()) {
    out.blend = std::move(blend).value();
    out.blendable = true;
  } else {
    out.blend.independent = budget.independent;
    out.blend.not_estimated =
        std::make_shared<const std::vector<std::string>>(budget.not_estimated);
  }
  if (const Component* white = budget.Find("white_standard"); white != nullptr) {
    out.white_standard = white->contribution;
  }
  return out;
}

}  // namespace brdf::uncertainty
