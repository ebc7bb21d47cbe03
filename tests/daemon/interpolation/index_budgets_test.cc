// daemon/index/budgets: the index holds what the blend needs of each reading's budget
// (BudgetForBlend), blends of it equal blends of the whole budget, and BudgetList::bytes counts
// the heap the budgets really hold (the index cache's bound relies on it).
#include <gtest/gtest.h>
#include <malloc.h>

#include <memory>
#include <string>
#include <vector>

#include "core/uncertainty/blend.h"
#include "daemon/index/budgets.h"

namespace brdf::daemon {
namespace {

constexpr int kBands = 101;  // the PR-650's 380–780 nm in 4 nm steps

std::vector<double> Bands(double base) {
  std::vector<double> v(kBands);
  for (int k = 0; k < kBands; ++k) v[k] = base * (1 + 0.01 * k);
  return v;
}

// A budget shaped like a paper-grid reading's as brdfd stores it: 8 components (2 independent),
// 3 components not estimated; reading `id` of a session whose reference is reading `reference`.
uncertainty::ReadingBudget PaperGridBudget(std::int64_t id, std::int64_t reference) {
  using uncertainty::Sharing;
  const struct {
    const char* name;
    Sharing kind;
    std::int64_t through;
  } parts[] = {{"sample_signal", Sharing::kIndependent, 0},
               {"reference_signal", Sharing::kReferenceReading, reference},
               {"white_standard", Sharing::kWhiteStandard, 1},
               {"reference_pose", Sharing::kReferenceReading, reference},
               {"lamp_drift", Sharing::kReferenceReading, reference},
               {"wavelength_scale", Sharing::kInstrument, 1},
               {"stray_light", Sharing::kInstrument, 1},
               {"pose_repeatability", Sharing::kIndependent, 0}};
  uncertainty::ReadingBudget b;
  b.value = Bands(0.2 + 1e-4 * static_cast<double>(id));
  double j = 1;
  for (const auto& p : parts) {
    b.components.push_back({p.name, {p.kind, p.through}, Bands(1e-3 * j++)});
  }
  b.combined = Bands(4e-3);
  b.independent = Bands(1.5e-3);
  b.not_estimated = {
      "dark_signal: the reading names no dark reading (ambient light is not removed)",
      "pose_gamma: no neighbouring reading along gamma to estimate the gradient (zero for an "
      "isotropic sample on gamma)",
      "pose_delta: no neighbouring reading along delta to estimate the gradient (zero for an "
      "isotropic sample on gamma)"};
  return b;
}

TEST(IndexBudgets, BlendsOfTheKeptPartEqualBlendsOfTheWholeBudgets) {
  std::vector<uncertainty::ReadingBudget> whole, kept;
  for (int i = 0; i < 4; ++i) whole.push_back(PaperGridBudget(10 + i, i < 2 ? 1 : 2));
  for (const auto& b : whole) kept.push_back(BudgetForBlend(b));
  EXPECT_TRUE(kept[0].value.empty());
  EXPECT_EQ(kept[0].components.size(), 6u);  // the two independent ones are in `independent`
  const double weights[] = {0.4, 0.3, 0.2, 0.1};
  std::vector<uncertainty::BlendVertex> of_whole, of_kept;
  for (int i = 0; i < 4; ++i) {
    of_whole.push_back({10 + i, weights[i], &whole[i]});
    of_kept.push_back({10 + i, weights[i], &kept[i]});
  }
  of_whole.push_back({10, 0.05, &whole[0]});  // a mirrored copy of reading 10
  of_kept.push_back({10, 0.05, &kept[0]});
  Result<uncertainty::BlendedUncertainty> a =
      uncertainty::BlendMeasurementUncertainty(of_whole, kBands);
  Result<uncertainty::BlendedUncertainty> b =
      uncertainty::BlendMeasurementUncertainty(of_kept, kBands);
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  EXPECT_EQ(a->measurement, b->measurement);
  EXPECT_EQ(a->shared, b->shared);
  EXPECT_EQ(a->not_estimated, b->not_estimated);
}

// The heap in use grows by what bytes() says, within 10 %, for a paper-grid session's 2,112
// budgets, whole or as the index keeps them; and the kept ones hold less than 4/5 of the whole.
TEST(IndexBudgets, BytesCountTheHeapTheBudgetsHold) {
  auto held = [](bool for_blend, std::size_t* heap) {
    malloc_trim(0);
    const std::size_t before = mallinfo2().uordblks;
    auto list = std::make_unique<BudgetList>();
    for (int i = 0; i < 2112; ++i) {
      uncertainty::ReadingBudget b = PaperGridBudget(i, 1 + i / 64);
      list->Add(std::make_shared<const uncertainty::ReadingBudget>(for_blend ? BudgetForBlend(b)
                                                                             : std::move(b)));
    }
    malloc_trim(0);
    *heap = mallinfo2().uordblks - before;
    return list->bytes();
  };
  std::size_t whole_heap = 0, kept_heap = 0;
  const std::size_t whole = held(false, &whole_heap);
  const std::size_t kept = held(true, &kept_heap);
  EXPECT_NEAR(static_cast<double>(whole), static_cast<double>(whole_heap), 0.1 * whole_heap);
  EXPECT_NEAR(static_cast<double>(kept), static_cast<double>(kept_heap), 0.1 * kept_heap);
  EXPECT_LT(kept, whole * 4 / 5);
  std::printf("2112 paper-grid budgets: whole %.1f MB (heap %.1f), kept %.1f MB (heap %.1f)\n",
              whole / 1048576.0, whole_heap / 1048576.0, kept / 1048576.0, kept_heap / 1048576.0);
}

}  // namespace
}  // namespace brdf::daemon
