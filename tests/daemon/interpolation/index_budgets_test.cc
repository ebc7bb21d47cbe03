// daemon/index/budgets: the index holds what the blend needs of each reading's budget in the
// blend's form (uncertainty::BlendBudget), blends of it equal blends of the whole budgets with
// their shared contributions rounded to float, and BudgetList::bytes counts the heap the budgets
// really hold (the index cache's bound relies on it).
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

// `b` with its shared components' contributions rounded to float, as the index keeps them.
uncertainty::ReadingBudget WithFloatContributions(uncertainty::ReadingBudget b) {
  for (uncertainty::Component& c : b.components) {
    if (c.shared.kind == uncertainty::Sharing::kIndependent) continue;
    for (double& u : c.contribution) u = static_cast<float>(u);
  }
  return b;
}

TEST(IndexBudgets, BlendsOfTheIndexFormAreBlendsOfTheBudgetsRoundedToFloat) {
  std::vector<uncertainty::ReadingBudget> whole, rounded;
  BudgetList list;
  for (int i = 0; i < 4; ++i) {
    whole.push_back(PaperGridBudget(10 + i, i < 2 ? 1 : 2));
    rounded.push_back(WithFloatContributions(whole.back()));
    list.Add(&whole.back());
  }
  ASSERT_NE(list.at(0), nullptr);
  EXPECT_EQ(list.at(0)->keys.size(), 6u);  // the two independent ones are in `independent`
  // Readings with the same entries share one list of them.
  EXPECT_EQ(list.at(0)->not_estimated, list.at(3)->not_estimated);
  const double weights[] = {0.4, 0.3, 0.2, 0.1};
  std::vector<uncertainty::BlendVertex> of_whole, of_rounded;
  std::vector<uncertainty::BlendBudgetVertex> of_index;
  for (std::size_t i = 0; i < 4; ++i) {
    of_whole.push_back({10 + static_cast<int>(i), weights[i], &whole[i]});
    of_rounded.push_back({10 + static_cast<int>(i), weights[i], &rounded[i]});
    of_index.push_back({10 + static_cast<int>(i), weights[i], list.at(i)});
  }
  of_whole.push_back({10, 0.05, &whole[0]});  // a mirrored copy of reading 10
  of_rounded.push_back({10, 0.05, &rounded[0]});
  of_index.push_back({10, 0.05, list.at(0)});
  Result<uncertainty::BlendedUncertainty> a =
      uncertainty::BlendMeasurementUncertainty(of_rounded, kBands);
  uncertainty::BlendedUncertainty b;
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  ASSERT_TRUE(uncertainty::BlendMeasurementUncertainty(of_index, kBands, &b).ok());
  // The same operations on the same (widened) values: the same bits.
  EXPECT_EQ(a->measurement, b.measurement);
  EXPECT_EQ(a->shared, b.shared);
  EXPECT_EQ(a->not_estimated, b.not_estimated);
  // Against the budgets' doubles: every contribution here is positive, so each sum of them, its
  // square and its root are off by at most a float's rounding, 2⁻²⁴ relative.
  Result<uncertainty::BlendedUncertainty> exact =
      uncertainty::BlendMeasurementUncertainty(of_whole, kBands);
  ASSERT_TRUE(exact.ok()) << exact.status().ToString();
  bool some_differ = false;
  for (int k = 0; k < kBands; ++k) {
    const double m = exact->measurement[static_cast<std::size_t>(k)];
    EXPECT_NEAR(b.measurement[static_cast<std::size_t>(k)], m, 0x1p-24 * m) << "band " << k;
    some_differ = some_differ || b.measurement[static_cast<std::size_t>(k)] != m;
  }
  EXPECT_TRUE(some_differ) << "the index's rows are not floats";
}

// A budget whose parts do not have the same number of bands is not estimated in the index.
TEST(IndexBudgets, ABudgetWithPartsOfOtherSizesIsNotEstimated) {
  uncertainty::ReadingBudget b = PaperGridBudget(10, 1);
  b.components[2].contribution.pop_back();
  BudgetList list;
  list.Add(&b);
  list.Add(nullptr);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list.at(0), nullptr);
  EXPECT_EQ(list.at(1), nullptr);
}

// The heap in use grows by what bytes() says, within 10 %, for a paper-grid session's 2,112
// budgets as the index keeps them; and they hold less than half of the whole budgets' heap.
TEST(IndexBudgets, BytesCountTheHeapTheBudgetsHold) {
  malloc_trim(0);
  std::size_t before = mallinfo2().uordblks;
  std::vector<std::shared_ptr<const uncertainty::ReadingBudget>> whole;
  for (int i = 0; i < 2112; ++i) {
    whole.push_back(
        std::make_shared<const uncertainty::ReadingBudget>(PaperGridBudget(i, 1 + i / 64)));
  }
  malloc_trim(0);
  const std::size_t whole_heap = mallinfo2().uordblks - before;
  before = mallinfo2().uordblks;
  auto list = std::make_unique<BudgetList>();
  for (const auto& b : whole) list->Add(b.get());
  malloc_trim(0);
  const std::size_t kept_heap = mallinfo2().uordblks - before;
  const std::size_t kept = list->bytes();
  EXPECT_NEAR(static_cast<double>(kept), static_cast<double>(kept_heap), 0.1 * kept_heap);
  EXPECT_LT(kept, whole_heap / 2);
  std::printf("2112 paper-grid budgets: whole (heap) %.1f MB, kept %.1f MB (heap %.1f)\n",
              whole_heap / 1048576.0, kept / 1048576.0, kept_heap / 1048576.0);
}

}  // namespace
}  // namespace brdf::daemon
