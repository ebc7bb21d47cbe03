// daemon/index/budgets: the index holds what the blend needs of each reading's budget in the
// blend's form (uncertainty::BlendBudget), blends of it equal the GUM sums of the whole budgets to
// a float's rounding of their shared contributions, and BudgetList::bytes counts the heap the
// budgets really hold (the index cache's bound relies on it).
#include <gtest/gtest.h>
#include <malloc.h>

#include <cmath>
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

TEST(IndexBudgets, BlendsOfTheIndexFormAreTheBudgetsBlendsToAFloatsRounding) {
  std::vector<uncertainty::ReadingBudget> whole;
  BudgetList list;
  for (int i = 0; i < 4; ++i) whole.push_back(PaperGridBudget(10 + i, i < 2 ? 1 : 2));
  for (const uncertainty::ReadingBudget& b : whole) list.Add(&b);
  ASSERT_NE(list.at(0), nullptr);
  EXPECT_EQ(list.at(0)->keys.size(), 6u);  // the two independent ones are in `independent`
  // Readings with the same entries share one list of them.
  EXPECT_EQ(list.at(0)->not_estimated, list.at(3)->not_estimated);
  // A copy (the next snapshot's list) adding more budgets codes their names alike.
  BudgetList next = list;
  next.Add(&whole[0]);
  EXPECT_EQ(next.at(4)->keys, list.at(0)->keys);
  const double weights[] = {0.4, 0.3, 0.2, 0.1};
  std::vector<uncertainty::BlendVertex> of_index;
  for (std::size_t i = 0; i < 4; ++i) {
    of_index.push_back({10 + static_cast<int>(i), weights[i], list.at(i)});
  }
  of_index.push_back({10, 0.05, list.at(0)});  // a mirrored copy of reading 10: weight 0.45
  uncertainty::BlendedUncertainty b;
  ASSERT_TRUE(uncertainty::BlendMeasurementUncertainty(of_index, kBands, &b).ok());
  EXPECT_EQ(b.not_estimated, whole[0].not_estimated);
  // Against the GUM §5.2 sums of the budgets' doubles written out: every contribution here is
  // positive, so each sum of them, its square and its root are off by at most a float's
  // rounding, 2⁻²⁴ relative.
  const double w[] = {0.45, 0.3, 0.2, 0.1};
  bool some_differ = false;
  for (std::size_t k = 0; k < static_cast<std::size_t>(kBands); ++k) {
    double independent2 = 0, shared2 = 0;
    for (std::size_t i = 0; i < 4; ++i) {
      independent2 += w[i] * w[i] * whole[i].independent[k] * whole[i].independent[k];
    }
    // Components 1–6 are shared: the white standard and the instrument's by all four readings,
    // the reference's (components 1, 3, 4) by readings 0–1 (reference 1) and 2–3 (reference 2).
    for (std::size_t j = 1; j <= 6; ++j) {
      const bool per_reference = j == 1 || j == 3 || j == 4;
      for (const auto& group : per_reference
                                   ? std::vector<std::vector<std::size_t>>{{0, 1}, {2, 3}}
                                   : std::vector<std::vector<std::size_t>>{{0, 1, 2, 3}}) {
        double sum = 0;
        for (std::size_t i : group) sum += w[i] * whole[i].components[j].contribution[k];
        shared2 += sum * sum;
      }
    }
    const double m = std::sqrt(shared2 + independent2);
    EXPECT_NEAR(b.measurement[k], m, 0x1p-24 * m) << "band " << k;
    EXPECT_NEAR(b.shared[k], std::sqrt(shared2), 0x1p-24 * std::sqrt(shared2)) << "band " << k;
    some_differ = some_differ || b.measurement[k] != m;
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
