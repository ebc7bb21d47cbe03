// IndexCache takes committed readings from the commit event, not from the store: a record handed
// over by OnReading is folded in as it is (here one the store never saw, so a read-back would
// miss it), and a session's stored plan that no longer parses is reported as session_plan.h says.
#include <gtest/gtest.h>

#include "daemon/index/cache.h"
#include "daemon/sessions/session_plan.h"
#include "storage/session_store.h"
#include "tests/support/test_env.h"

namespace brdf::daemon {
namespace {

const WavelengthGrid kGrid{400, 100, 4};

class IndexCacheFoldTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = storage::SessionStore::Open(dir_.file("fold.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
  }

  std::int64_t MakeSession(const std::string& plan_json, int steps) {
    storage::NewSession s;
    s.name = "fold test";
    s.plan_kind = "pose_list";
    s.plan_json = plan_json;
    s.created_by_role = "operator";
    std::vector<storage::StepRecord> records;
    for (int i = 0; i < steps; ++i) {
      storage::StepRecord r;
      r.step_index = i;
      r.kind = i == 0 ? storage::StepKind::kReference : storage::StepKind::kSample;
      records.push_back(r);
    }
    Result<std::int64_t> id = store_->CreateSession(s, records);
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    EXPECT_TRUE(store_->SetSessionState(*id, SessionState::kRunning, "test").ok());
    return *id;
  }

  storage::ReadingRecord Record(storage::ReadingKind kind, Directions d, double level) {
    storage::ReadingRecord r;
    r.kind = kind;
    r.directions = d;
    r.grid = kGrid;
    r.spectrum = {level, level, level, level};
    return r;
  }

  testing::TempDir dir_{"index-cache-fold-test"};
  std::shared_ptr<storage::SessionStore> store_;
};

TEST_F(IndexCacheFoldTest, HandedOverRecordsAreFoldedWithoutReadingTheStore) {
  const std::int64_t session =
      MakeSession(R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]}})", 4);
  Result<std::int64_t> ref =
      store_->CompleteStepWithReading(session, 0, Record(storage::ReadingKind::kReference, {}, 2));
  ASSERT_TRUE(ref.ok()) << ref.status().ToString();
  storage::ReadingRecord first = Record(storage::ReadingKind::kSample, {20, 0, 30, 90}, 1);
  first.reference_reading_id = *ref;
  ASSERT_TRUE(store_->CompleteStepWithReading(session, 1, first).ok());

  IndexCache cache(store_);
  auto loaded = cache.Get(session, Quantity::kReflectance, interp::Method::kNearest, {});
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ((*loaded)->samples->size(), 1u);
  const std::uint64_t read = cache.stats().readings_read;
  EXPECT_EQ(read, 2u);

  // A record as the executor hands it over after its commit, never written to this store.
  storage::ReadingRecord landed = Record(storage::ReadingKind::kSample, {40, 0, 50, 120}, 0.5);
  landed.id = 1000;
  landed.session_id = session;
  landed.step_index = 2;
  landed.reference_reading_id = *ref;
  cache.OnReading(session, landed);
  auto next = cache.Get(session, Quantity::kReflectance, interp::Method::kNearest, {});
  ASSERT_TRUE(next.ok()) << next.status().ToString();
  EXPECT_EQ((*next)->samples->size(), 2u);
  EXPECT_EQ((*next)->through_reading_id, 1000);
  const double at[] = {40, 50, 120};
  const interp::Interpolation answer = (*next)->interpolator->Evaluate(at);
  ASSERT_FALSE(answer.vertices.empty());
  EXPECT_EQ(answer.vertices.at(0).id, 1000);
  EXPECT_DOUBLE_EQ(answer.spectrum.at(0), 0.25);  // its reflectance, from the folded reference
  EXPECT_EQ(cache.stats().readings_read, read);   // nothing read back
  EXPECT_EQ(cache.stats().readings_folded, 1u);
}

TEST_F(IndexCacheFoldTest, AStoredPlanThatNoLongerParsesIsReportedOneWay) {
  const std::int64_t session = MakeSession("{not json", 2);
  Result<storage::SessionRecord> record = store_->GetSession(session);
  ASSERT_TRUE(record.ok());
  Result<SessionPlan> plan = ParseSessionPlan(*record);
  ASSERT_FALSE(plan.ok());
  EXPECT_EQ(plan.status().code(), StatusCode::kInternal);
  const std::string expected =
      "session " + std::to_string(session) + ": its stored plan does not parse: ";
  EXPECT_EQ(plan.status().message().rfind(expected, 0), 0u) << plan.status().message();

  IndexCache cache(store_);
  auto got = cache.Get(session, Quantity::kBrdf, interp::Method::kOctant, {});
  EXPECT_EQ(got.status().code(), StatusCode::kInternal);
  EXPECT_EQ(got.status().message(), plan.status().message());
}

}  // namespace
}  // namespace brdf::daemon
