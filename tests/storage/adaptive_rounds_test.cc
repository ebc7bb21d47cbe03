// SessionStore's adaptive rounds (schema v6): a round is stored with its steps in one transaction,
// numbered after the session's steps; a round stored twice, or out of order, is refused with
// nothing written; the picks read back exactly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "storage/session_store.h"
#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;
using testing::MakeNewSession;
using testing::MakeSteps;
using testing::TempDir;

// Steps first … first + n − 1 (moves and samples).
std::vector<StepRecord> StepsFrom(int first, int n) {
  std::vector<StepRecord> steps = MakeSteps(first + n);
  return std::vector<StepRecord>(steps.begin() + first, steps.end());
}

RoundRecord Round(std::int64_t session, int number, int first_step) {
  RoundRecord r;
  r.session_id = session;
  r.round = number;
  r.first_step = first_step;
  r.picks = {{Pose{12.5, -35, 0, 11.25}, 0.0123456789012345}, {Pose{1.0 / 3, 170, 0, 22.5}, 1e-7}};
  r.predicted_gain = 0.0123457789012345;
  r.uncertainty_left = 0.0712;
  r.readings_used = 15;
  return r;
}

class AdaptiveRoundsStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = SessionStore::Open(dir_.File("brdfd.db"));
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(store).value();
    auto id = store_->CreateSession(MakeNewSession(), MakeSteps(5));
    ASSERT_TRUE(id.ok()) << id.status().ToString();
    id_ = *id;
    ASSERT_TRUE(store_->SetSessionState(id_, SessionState::kRunning, "started").ok());
  }

  TempDir dir_;
  std::unique_ptr<SessionStore> store_;
  std::int64_t id_ = 0;
};

TEST_F(AdaptiveRoundsStoreTest, StoresTheRoundWithItsStepsAndReadsItBackExactly) {
  ASSERT_TRUE(store_->AppendRound(Round(id_, 1, 5), StepsFrom(5, 4)).ok());
  auto session = store_->GetSession(id_);
  ASSERT_TRUE(session.ok());
  EXPECT_EQ(session->total_steps, 9);
  auto steps = store_->GetSteps(id_);
  ASSERT_TRUE(steps.ok());
  ASSERT_EQ(steps->size(), 9u);
  EXPECT_EQ((*steps)[8].step_index, 8);
  EXPECT_EQ((*steps)[8].state, StepState::kPending);

  auto rounds = store_->GetRounds(id_);
  ASSERT_TRUE(rounds.ok()) << rounds.status().ToString();
  ASSERT_EQ(rounds->size(), 1u);
  const RoundRecord& r = rounds->front();
  const RoundRecord want = Round(id_, 1, 5);
  EXPECT_EQ(r.round, 1);
  EXPECT_EQ(r.first_step, 5);
  EXPECT_EQ(r.step_count, 4);
  ASSERT_EQ(r.picks.size(), want.picks.size());
  for (std::size_t i = 0; i < r.picks.size(); ++i) {
    EXPECT_EQ(r.picks[i].pose, want.picks[i].pose);
    EXPECT_EQ(r.picks[i].predicted_gain, want.picks[i].predicted_gain);
  }
  EXPECT_EQ(r.predicted_gain, want.predicted_gain);
  EXPECT_EQ(r.uncertainty_left, want.uncertainty_left);
  EXPECT_EQ(r.readings_used, 15);
  EXPECT_GT(r.created_at, 0);

  auto report = store_->CheckSession(id_);
  ASSERT_TRUE(report.ok());
  EXPECT_TRUE(report->ok()) << report->Summary();
}

TEST_F(AdaptiveRoundsStoreTest, ARoundStoredTwiceOrOutOfPlaceIsRefusedAndWritesNothing) {
  ASSERT_TRUE(store_->AppendRound(Round(id_, 1, 5), StepsFrom(5, 4)).ok());
  Status twice = store_->AppendRound(Round(id_, 1, 9), StepsFrom(9, 4));
  EXPECT_EQ(twice.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(twice.message(), HasSubstr("the next round is 2 from step 9"));
  Status gap = store_->AppendRound(Round(id_, 2, 7), StepsFrom(7, 4));
  EXPECT_EQ(gap.code(), StatusCode::kFailedPrecondition);  // steps 7… would overlap 7 and 8
  Status misnumbered = store_->AppendRound(Round(id_, 2, 9), StepsFrom(10, 2));
  EXPECT_EQ(misnumbered.code(), StatusCode::kInvalidArgument);
  auto session = store_->GetSession(id_);
  ASSERT_TRUE(session.ok());
  EXPECT_EQ(session->total_steps, 9);
  auto rounds = store_->GetRounds(id_);
  ASSERT_TRUE(rounds.ok());
  EXPECT_EQ(rounds->size(), 1u);

  ASSERT_TRUE(store_->SetSessionState(id_, SessionState::kAborted, "stop").ok());
  Status ended = store_->AppendRound(Round(id_, 2, 9), StepsFrom(9, 2));
  EXPECT_EQ(ended.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(ended.message(), HasSubstr("the session has ended"));
}

}  // namespace
}  // namespace brdf::storage
