// storage/session_readings.h: a stored session handed out as core/readings values, with what the
// derivation needs of the session itself -- ρw as stored, and ρw(λ) from the plan's sample block.
#include "storage/session_readings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/uncertainty/loaded_budget.h"
#include "storage/session_store.h"
#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using testing::MakeBudget;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using testing::TempDir;

TEST(SessionReadingsTest, TheSampleBlocksWhiteSpectrumComesWithTheReadings) {
  TempDir dir;
  auto store = SessionStore::Open(dir.File("rig.db"));
  ASSERT_TRUE(store.ok());
  NewSession n = MakeNewSession();
  n.plan_json = R"({"name": "gloss", "sample": {"id": "P-1", "whiteReflectanceSpectrum":
    {"startNm": 380, "stepNm": 200, "values": [0.95, 0.97, 0.99]}}})";
  n.white_reflectance = 0.5;
  auto id = (*store)->CreateSession(n, MakeSteps(3));
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE((*store)->SetSessionState(*id, SessionState::kRunning, "").ok());
  ASSERT_TRUE(
      (*store)->CompleteStepWithReading(*id, 1, MakeReading(1, ReadingKind::kReference)).ok());
  Result<SessionReadings> s = LoadSessionReadings(**store, *id);
  ASSERT_TRUE(s.ok()) << s.status().ToString();
  EXPECT_EQ(s->white_reflectance, 0.5);
  ASSERT_TRUE(s->white_reflectance_spectrum.has_value());
  EXPECT_EQ(s->white_reflectance_spectrum->grid.count, 3u);
  EXPECT_EQ(s->white_reflectance_spectrum->values[2], 0.99);
  EXPECT_EQ(s->readings.size(), 1u);

  // No sample block: no spectrum; a plan that no longer parses is an internal error naming it.
  NewSession plain = MakeNewSession();
  plain.plan_json = R"({"name": "plain"})";
  auto other = (*store)->CreateSession(plain, MakeSteps(2));
  ASSERT_TRUE(other.ok());
  Result<SessionReadings> none = LoadSessionReadings(**store, *other);
  ASSERT_TRUE(none.ok()) << none.status().ToString();
  EXPECT_FALSE(none->white_reflectance_spectrum.has_value());
  auto broken = (*store)->CreateSession(MakeNewSession(), MakeSteps(2));  // "kind": not a Plan key
  Result<SessionReadings> bad = LoadSessionReadings(**store, *broken);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("stored plan does not parse"), std::string::npos);
}

// A reading's stored budget reaches the exports and fits: its combined u as brdf_u, and the part
// the reflectance shares (without the white standard's and the reference pose's terms).
TEST(SessionReadingsTest, AReadingsBudgetComesWithItAsItsStandardUncertainty) {
  const WavelengthGrid grid{500, 100, 2};
  ReadingRecord rec = MakeReading(2, ReadingKind::kSample);
  uncertainty::ReadingBudget b = MakeBudget(2, grid, 1);
  b.components.push_back(
      {"white_standard", {uncertainty::Sharing::kWhiteStandard, 1}, {4e-4, 5e-4}});
  b.components.push_back(
      {"reference_pose", {uncertainty::Sharing::kReferenceReading, 1}, {1e-4, 1e-4}});
  for (std::size_t i = 0; i < grid.count; ++i) {
    double sum = 0;
    for (const uncertainty::Component& c : b.components)
      sum += c.contribution[i] * c.contribution[i];
    b.combined[i] = std::sqrt(sum);
  }
  rec.uncertainty = b;
  const Reading r = ToReading(rec);
  EXPECT_EQ(r.brdf_u, b.combined);
  ASSERT_EQ(r.brdf_u_of_ratio.size(), 2u);
  for (std::size_t i = 0; i < grid.count; ++i) {
    EXPECT_DOUBLE_EQ(r.brdf_u_of_ratio[i],
                     std::hypot(b.components[0].contribution[i], b.components[1].contribution[i]));
  }
  // Not estimated: nothing.
  EXPECT_TRUE(ToReading(MakeReading(3, ReadingKind::kSample)).brdf_u.empty());
}

// What the exports read of a stored budget of the BRDF is kept in their form, made by the one
// maker the session's load passes (Reading::budget): the blend form ToBlendBudget gives (the grid
// export's cells blend it as Interpolate does), the white standard's contribution in double (the
// MERL and RGL sidecar's relative_white_standard), one not_estimated list for consecutive readings
// with the same entries. Without a maker (the daemon's index folding records), and for a budget of
// another quantity, nothing is kept.
TEST(SessionReadingsTest, ABudgetOfTheBrdfIsKeptInTheExportsForm) {
  const WavelengthGrid grid{500, 100, 2};
  ReadingRecord first = MakeReading(4, ReadingKind::kSample);
  first.uncertainty = MakeBudget(4, grid, 1);  // step 4: of the BRDF
  first.uncertainty->components.push_back(
      {"white_standard", {uncertainty::Sharing::kWhiteStandard, 1}, {4e-4, 5e-4}});
  ReadingRecord second = MakeReading(8, ReadingKind::kSample);
  second.uncertainty = MakeBudget(8, grid, 1);
  uncertainty::BlendBudgetMaker maker;
  const Reading a = ToReading(first, &maker);
  const Reading b = ToReading(second, &maker);
  ASSERT_NE(a.budget, nullptr);
  ASSERT_NE(b.budget, nullptr);
  EXPECT_TRUE(a.budget->blendable);
  uncertainty::NameCodes codes;
  Result<uncertainty::BlendBudget> expected = uncertainty::ToBlendBudget(*first.uncertainty, codes);
  ASSERT_TRUE(expected.ok());
  EXPECT_EQ(a.budget->blend.bands, expected->bands);
  EXPECT_EQ(a.budget->blend.independent, expected->independent);
  EXPECT_EQ(a.budget->blend.keys, expected->keys);
  EXPECT_EQ(a.budget->blend.shared_rows, expected->shared_rows);
  EXPECT_EQ(*a.budget->blend.not_estimated, first.uncertainty->not_estimated);
  EXPECT_EQ(a.budget->white_standard, (std::vector<double>{4e-4, 5e-4}));
  EXPECT_TRUE(b.budget->white_standard.empty());
  EXPECT_EQ(a.budget->blend.not_estimated, b.budget->blend.not_estimated) << "one list, shared";

  EXPECT_EQ(ToReading(first).budget, nullptr) << "no maker: not kept";
  EXPECT_EQ(ToReading(first).brdf_u, first.uncertainty->combined);
  ReadingRecord reflectance = MakeReading(5, ReadingKind::kSample);
  reflectance.uncertainty = MakeBudget(5, grid, 1);  // of the reflectance
  EXPECT_EQ(ToReading(reflectance, &maker).budget, nullptr);

  // A budget whose parts disagree in bands: not blendable, its notes and independent part kept.
  ReadingRecord bad = second;
  bad.uncertainty->components[1].contribution.push_back(1e-5);
  const Reading c = ToReading(bad, &maker);
  ASSERT_NE(c.budget, nullptr);
  EXPECT_FALSE(c.budget->blendable);
  EXPECT_EQ(c.budget->blend.independent, bad.uncertainty->independent);
  EXPECT_EQ(*c.budget->blend.not_estimated, bad.uncertainty->not_estimated);
}

// A session keeps one wavelength grid, its first reading's (issue 41): the session record says
// it once there is a reading, and a reading on another grid is refused without being stored.
TEST(SessionReadingsTest, ASessionKeepsItsFirstReadingsGridAndRefusesAnother) {
  TempDir dir;
  auto store = SessionStore::Open(dir.File("rig.db"));
  ASSERT_TRUE(store.ok());
  auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(4));
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE((*store)->SetSessionState(*id, SessionState::kRunning, "").ok());
  Result<SessionRecord> before = (*store)->GetSession(*id);
  ASSERT_TRUE(before.ok());
  EXPECT_FALSE(before->grid.has_value()) << "no reading yet, no grid";

  const WavelengthGrid cs2000{380, 1, 401};
  ASSERT_TRUE((*store)
                  ->CompleteStepWithReading(*id, 1, MakeReading(1, ReadingKind::kReference, cs2000))
                  .ok());
  Result<std::int64_t> mixed = (*store)->CompleteStepWithReading(
      *id, 2, MakeReading(2, ReadingKind::kSample, WavelengthGrid::Pr650()));
  ASSERT_FALSE(mixed.ok());
  EXPECT_EQ(mixed.status().code(), StatusCode::kFailedPrecondition);
  const std::string& why = mixed.status().message();
  EXPECT_NE(why.find("380–780 nm every 4 nm (101 bands)"), std::string::npos) << why;
  EXPECT_NE(why.find("380–780 nm every 1 nm (401 bands)"), std::string::npos) << why;
  EXPECT_NE(why.find("start a new session"), std::string::npos) << why;
  // Nothing of it was kept: the step is still pending and takes a reading on the session's grid.
  ASSERT_TRUE(
      (*store)->CompleteStepWithReading(*id, 2, MakeReading(2, ReadingKind::kSample, cs2000)).ok());
  auto readings = (*store)->GetReadings(*id, 0, 10);
  ASSERT_TRUE(readings.ok());
  ASSERT_EQ(readings->size(), 2u);
  for (const ReadingRecord& r : *readings) EXPECT_EQ(r.grid, cs2000);

  Result<SessionRecord> after = (*store)->GetSession(*id);
  ASSERT_TRUE(after.ok());
  ASSERT_TRUE(after->grid.has_value());
  EXPECT_EQ(*after->grid, cs2000);
  auto all = (*store)->ListSessions();
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 1u);
  EXPECT_EQ(all->front().grid, std::optional<WavelengthGrid>(cs2000));

  // Another session is free to have another grid.
  auto other = (*store)->CreateSession(MakeNewSession("pr650"), MakeSteps(3));
  ASSERT_TRUE(other.ok());
  ASSERT_TRUE((*store)->SetSessionState(*other, SessionState::kRunning, "").ok());
  ASSERT_TRUE(
      (*store)->CompleteStepWithReading(*other, 1, MakeReading(1, ReadingKind::kReference)).ok());
  EXPECT_EQ((*store)->GetSession(*other)->grid,
            std::optional<WavelengthGrid>(WavelengthGrid::Pr650()));
}

}  // namespace
}  // namespace brdf::storage
