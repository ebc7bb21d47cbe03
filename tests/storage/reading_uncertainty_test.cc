// Schema v5: a sample reading's uncertainty budget is stored with it in the same transaction and
// read back whole; a reading without one -- and every reading of a file from before v5 -- reads as
// "not estimated", never as zero; a budget that does not fit its reading is refused and leaves
// nothing behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "storage/schema.h"
#include "storage/session_store.h"
#include "storage/uncertainty_columns.h"
#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using testing::TempDir;
using uncertainty::Component;
using uncertainty::ReadingBudget;
using uncertainty::SharedThrough;
using uncertainty::Sharing;

const WavelengthGrid kGrid{500, 10, 3};

ReadingBudget MakeBudget() {
  ReadingBudget b;
  b.quantity = Quantity::kBrdf;
  b.components = {
      Component{"sample_signal", {}, {1e-4, 2e-4, 3e-4}},
      Component{"reference_signal", {Sharing::kReferenceReading, 1}, {-1e-5, -2e-5, -3e-5}},
      Component{"white_standard", {Sharing::kWhiteStandard, 7}, {5e-4, 6e-4, 7e-4}},
  };
  b.value = {0.10, 0.12, 0.14};
  b.combined = {0.00051, 0.00064, 0.00077};
  b.independent = {1e-4, 2e-4, 3e-4};
  b.not_estimated = {"pose: the quantity's gradient over the pose is not known"};
  return b;
}

void ExpectSameBudget(const ReadingBudget& got, const ReadingBudget& want) {
  EXPECT_EQ(got.quantity, want.quantity);
  EXPECT_EQ(got.combined, want.combined);
  EXPECT_EQ(got.independent, want.independent);
  EXPECT_EQ(got.not_estimated, want.not_estimated);
  ASSERT_EQ(got.components.size(), want.components.size());
  for (std::size_t i = 0; i < want.components.size(); ++i) {
    EXPECT_EQ(got.components[i].name, want.components[i].name);
    EXPECT_EQ(got.components[i].shared, want.components[i].shared);
    EXPECT_EQ(got.components[i].contribution, want.components[i].contribution);
  }
  EXPECT_EQ(got.value, want.value);
}

struct Fixture {
  TempDir dir;
  std::unique_ptr<SessionStore> store;
  std::int64_t session = 0;

  explicit Fixture(const std::string& name = "u.db") {
    auto opened = SessionStore::Open(dir.File(name));
    EXPECT_TRUE(opened.ok()) << opened.status().ToString();
    store = std::move(opened).value();
    auto id = store->CreateSession(MakeNewSession(), MakeSteps(4));
    EXPECT_TRUE(id.ok());
    session = *id;
    EXPECT_TRUE(store->SetSessionState(session, SessionState::kRunning, "").ok());
    EXPECT_TRUE(store->CompleteStep(session, 0).ok());
    EXPECT_TRUE(
        store->CompleteStepWithReading(session, 1, MakeReading(1, ReadingKind::kReference, kGrid))
            .ok());
  }
};

TEST(ReadingUncertaintyTest, StoredWithTheReadingAndReadBackWhole) {
  Fixture f;
  ReadingRecord sample = MakeReading(2, ReadingKind::kSample, kGrid);
  sample.reference_reading_id = 1;
  sample.uncertainty = MakeBudget();
  auto id = f.store->CompleteStepWithReading(f.session, 2, sample);
  ASSERT_TRUE(id.ok()) << id.status().ToString();
  auto one = f.store->GetReading(*id);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  ASSERT_TRUE(one->uncertainty.has_value());
  ExpectSameBudget(*one->uncertainty, MakeBudget());
  auto page = f.store->GetReadings(f.session, 0, 10);
  ASSERT_TRUE(page.ok());
  ASSERT_EQ(page->size(), 2u);
  EXPECT_FALSE((*page)[0].uncertainty.has_value());  // the reference: not estimated
  ASSERT_TRUE((*page)[1].uncertainty.has_value());
  ExpectSameBudget(*(*page)[1].uncertainty, MakeBudget());
}

TEST(ReadingUncertaintyTest, AReadingWithoutABudgetIsNotEstimatedNotZero) {
  Fixture f;
  ReadingRecord sample = MakeReading(2, ReadingKind::kSample, kGrid);
  auto id = f.store->CompleteStepWithReading(f.session, 2, sample);
  ASSERT_TRUE(id.ok());
  auto back = f.store->GetReading(*id);
  ASSERT_TRUE(back.ok());
  EXPECT_FALSE(back->uncertainty.has_value());
}

TEST(ReadingUncertaintyTest, ABudgetThatDoesNotFitIsRefusedAndNothingIsWritten) {
  Fixture f;
  ReadingRecord sample = MakeReading(2, ReadingKind::kSample, kGrid);
  sample.uncertainty = MakeBudget();
  sample.uncertainty->components[1].contribution.pop_back();
  auto id = f.store->CompleteStepWithReading(f.session, 2, sample);
  ASSERT_FALSE(id.ok());
  EXPECT_EQ(id.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(id.status().message(), HasSubstr("component reference_signal has 2 values"));
  EXPECT_THAT(id.status().message(), HasSubstr("step 2 of session"));
  EXPECT_EQ(*f.store->CountReadings(f.session), 1);
  EXPECT_EQ(**f.store->FirstUnfinishedStep(f.session), 2);
  // The same step takes the reading once the budget is right.
  sample.uncertainty = MakeBudget();
  EXPECT_TRUE(f.store->CompleteStepWithReading(f.session, 2, sample).ok());
}

TEST(ReadingUncertaintyTest, OnlySampleReadingsCarryABudget) {
  Fixture f;
  ReadingRecord reference = MakeReading(11, ReadingKind::kReference, kGrid);
  reference.uncertainty = MakeBudget();
  auto steps = MakeSteps(12);
  auto id = f.store->CreateSession(MakeNewSession("second"), steps);
  ASSERT_TRUE(id.ok());
  ASSERT_TRUE(f.store->SetSessionState(*id, SessionState::kRunning, "").ok());
  auto stored = f.store->CompleteStepWithReading(*id, 1, reference);
  ASSERT_FALSE(stored.ok());
  EXPECT_THAT(stored.status().message(), HasSubstr("only a sample reading"));
}

TEST(ReadingUncertaintyTest, ReadingsOfAVersion4FileReadAsNotEstimated) {
  TempDir dir;
  const std::string path = dir.File("v4.db");
  {
    auto db = Database::Open(path);
    ASSERT_TRUE(db.ok());
    ASSERT_TRUE(Migrate(**db, SchemaMigrations().first(4)).ok());
    ASSERT_TRUE((*db)
                    ->Exec("INSERT INTO sessions (name, plan_kind, plan_json, created_at, "
                           "total_steps, state) VALUES ('old', 'pose_list', '{}', 1.0, 1, "
                           "'completed')")
                    .ok());
    ASSERT_TRUE((*db)
                    ->Exec("INSERT INTO steps (session_id, step_index, kind, alpha, beta, gamma, "
                           "delta, label, state) VALUES (1, 0, 'sample', 0, 0, 0, 0, 's', 'done')")
                    .ok());
    ASSERT_TRUE((*db)
                    ->Exec("INSERT INTO readings (session_id, step_index, kind, alpha, beta, "
                           "gamma, delta, theta_i, phi_i, theta_o, phi_o, wl_start_nm, "
                           "wl_step_nm, wl_count, spectrum, quality_code, flagged, "
                           "integration_ms, attempts, note, meter_serial, recorded_at) VALUES "
                           "(1, 0, 'sample', 0, 0, 0, 0, 10, 0, 20, 180, 500, 10, 1, "
                           "zeroblob(8), 0, 0, 0, 1, '', 'x', 2.0)")
                    .ok());
  }
  auto store = SessionStore::Open(path);
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  auto readings = (*store)->GetReadings(1, 0, 10);
  ASSERT_TRUE(readings.ok()) << readings.status().ToString();
  ASSERT_EQ(readings->size(), 1u);
  EXPECT_FALSE((*readings)[0].uncertainty.has_value());
  auto db = Database::Open(path);
  ASSERT_TRUE(db.ok());
  EXPECT_EQ(*SchemaVersion(**db), LatestSchemaVersion());
}

TEST(ReadingUncertaintyTest, TheTableRefusesBlobsOfTheWrongLength) {
  Fixture f;
  auto db = Database::Open(f.dir.File("u.db"));
  ASSERT_TRUE(db.ok());
  Status bad = (*db)->Exec(
      "INSERT INTO reading_uncertainty (reading_id, quantity, bands, value, combined, independent, "
      "components, contributions) VALUES (1, 'brdf', 3, zeroblob(24), zeroblob(16), zeroblob(24), "
      "'', x'')");
  EXPECT_FALSE(bad.ok());
  Status quantity = (*db)->Exec(
      "INSERT INTO reading_uncertainty (reading_id, quantity, bands, value, combined, independent, "
      "components, contributions) VALUES (1, 'radiance', 3, zeroblob(24), zeroblob(24), "
      "zeroblob(24), '', x'')");
  EXPECT_FALSE(quantity.ok());
}

// A finished session's budgets estimated again replace the stored ones, all or none.
TEST(ReadingUncertaintyTest, BudgetsAreReplacedInOneTransactionAllOrNone) {
  Fixture f;
  ReadingRecord with = MakeReading(2, ReadingKind::kSample, kGrid);
  with.reference_reading_id = 1;
  with.uncertainty = MakeBudget();
  auto first = f.store->CompleteStepWithReading(f.session, 2, with);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  ReadingRecord without = MakeReading(3, ReadingKind::kSample, kGrid);
  auto second = f.store->CompleteStepWithReading(f.session, 3, without);
  ASSERT_TRUE(second.ok());

  ReadingBudget again = MakeBudget();
  again.components.push_back(Component{"pose_repeatability", {}, {1e-6, 2e-6, 3e-6}});
  again.not_estimated = {"pose_gamma: no neighbouring reading along gamma"};
  // One bad entry (the reference, which takes no budget) and nothing changes.
  Status refused = f.store->ReplaceReadingUncertainties(f.session, {{*first, again}, {1, again}});
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument) << refused.ToString();
  EXPECT_THAT(refused.message(), HasSubstr("reading 1 is a reference reading"));
  ExpectSameBudget(*f.store->GetReading(*first)->uncertainty, MakeBudget());
  // A reading of another session (or none) is not found; nothing changes either.
  refused = f.store->ReplaceReadingUncertainties(f.session, {{*first, again}, {999, again}});
  EXPECT_EQ(refused.code(), StatusCode::kNotFound) << refused.ToString();
  ExpectSameBudget(*f.store->GetReading(*first)->uncertainty, MakeBudget());
  // A budget that does not fit its reading's grid: refused, nothing changes.
  ReadingBudget short_one = again;
  short_one.combined.pop_back();
  refused = f.store->ReplaceReadingUncertainties(f.session, {{*first, short_one}});
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument) << refused.ToString();
  ExpectSameBudget(*f.store->GetReading(*first)->uncertainty, MakeBudget());

  // Both replaced: the one stored at commit and the one that had none.
  ASSERT_TRUE(
      f.store->ReplaceReadingUncertainties(f.session, {{*first, again}, {*second, again}}).ok());
  ExpectSameBudget(*f.store->GetReading(*first)->uncertainty, again);
  ExpectSameBudget(*f.store->GetReading(*second)->uncertainty, again);
  EXPECT_EQ(f.store->ReplaceReadingUncertainties(f.session + 100, {}).code(),
            StatusCode::kNotFound);
}

TEST(UncertaintyColumnsTest, RoundTripAndDamagedColumnsAreNamed) {
  auto columns = EncodeUncertainty(MakeBudget(), 3);
  ASSERT_TRUE(columns.ok()) << columns.status().ToString();
  EXPECT_EQ(columns->components,
            "sample_signal\tindependent\t0\nreference_signal\treference_reading\t1\n"
            "white_standard\twhite_standard\t7\n");
  EXPECT_EQ(columns->contributions.size(), 3u * 3u * 8u);
  auto back = DecodeUncertainty(*columns, 3);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ExpectSameBudget(*back, MakeBudget());

  UncertaintyColumns damaged = *columns;
  damaged.components = "sample_signal\tsomewhere\t0\n";
  damaged.contributions.resize(24);
  auto bad = DecodeUncertainty(damaged, 3);
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.status().message(), HasSubstr("somewhere"));
  damaged = *columns;
  damaged.contributions.pop_back();
  EXPECT_THAT(DecodeUncertainty(damaged, 3).status().message(), HasSubstr("contributions"));
  damaged = *columns;
  damaged.value.resize(16);
  EXPECT_THAT(DecodeUncertainty(damaged, 3).status().message(), HasSubstr("its value"));

  ReadingBudget negative = MakeBudget();
  negative.combined[0] = -1;
  EXPECT_THAT(EncodeUncertainty(negative, 3).status().message(), HasSubstr("combined"));
  ReadingBudget tab = MakeBudget();
  tab.components[0].name = "a\tb";
  EXPECT_FALSE(EncodeUncertainty(tab, 3).ok());
}

}  // namespace
}  // namespace brdf::storage
