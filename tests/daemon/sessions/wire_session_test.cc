// wire/: the one v1::Session builder brdfd's session manager and brdf-archive's catalogue share
// (what the record says, what the live server adds on top), and the enum mappings both ways.
#include <gtest/gtest.h>

#include <vector>

#include "daemon/sessions/session_plan.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/session.h"

namespace brdf::daemon {
namespace {

storage::SessionRecord Record(SessionState state) {
  storage::SessionRecord r;
  r.id = 42;
  r.name = "red paint";
  r.state = state;
  r.state_reason = "stored reason";
  r.created_at = 1700000000.25;
  r.total_steps = 3;
  r.done_steps = 1;
  r.uuid = "0f3c2a9e-5b1d-4c8e-9a7f-2d6b1e4c8a01";
  r.rig = "rig-a";
  return r;
}

// A move, a sample done, a sample pending: one of two samples done, step 2 the first pending.
std::vector<storage::StepRecord> Steps() {
  std::vector<storage::StepRecord> steps(3);
  steps[0].step_index = 0;
  steps[0].kind = storage::StepKind::kMove;
  steps[0].state = storage::StepState::kDone;
  steps[1].step_index = 1;
  steps[1].state = storage::StepState::kDone;
  steps[2].step_index = 2;
  return steps;
}

SessionPlan PlanWithSample() {
  v1::Plan plan;
  plan.set_name("red paint");
  plan.mutable_sample()->set_id("P-0042");
  plan.mutable_sample()->set_material("paint");
  return MakeSessionPlan(plan);
}

TEST(WireSessionTest, AnArchivedRecordShowsWhatTheRecordHoldsAndNoMore) {
  storage::SessionRecord rec = Record(SessionState::kAborted);
  rec.started_at = 1700000001.0;
  rec.finished_at = 1700000002.5;
  const std::vector<storage::StepRecord> steps = Steps();
  const SessionPlan plan = PlanWithSample();
  SessionFacts facts(rec);
  facts.plan = &plan;
  facts.steps = &steps;
  const v1::Session s = ToProtoSession(facts);

  EXPECT_EQ(s.session_id(), "42");
  EXPECT_EQ(s.state(), v1::SESSION_STATE_ABORTED);
  EXPECT_FALSE(s.has_plan()) << "ListSessions' form: no plan";
  EXPECT_EQ(s.sample().id(), "P-0042");
  EXPECT_EQ(s.rig(), "rig-a");
  EXPECT_EQ(s.uuid(), rec.uuid);
  EXPECT_EQ(s.progress().done_steps(), 1U);
  EXPECT_EQ(s.progress().total_steps(), 3U);
  EXPECT_EQ(s.progress().done_samples(), 1U);
  EXPECT_EQ(s.progress().total_samples(), 2U);
  EXPECT_EQ(s.current_step(), -1) << "an ended session has no current step";
  EXPECT_EQ(s.end_reason(), "stored reason");
  EXPECT_EQ(s.state_reason(), "stored reason");
  EXPECT_EQ(s.last_quality_code(), -1);
  EXPECT_FALSE(s.has_summary());
  EXPECT_EQ(s.eta_s(), 0);
  EXPECT_EQ(s.created_at().seconds(), 1700000000);
  EXPECT_EQ(s.created_at().nanos(), 250000000);
  EXPECT_EQ(s.finished_at().nanos(), 500000000);
}

TEST(WireSessionTest, TheLiveStateAndItsReasonWinOverTheRecord) {
  const storage::SessionRecord rec = Record(SessionState::kRunning);
  const std::vector<storage::StepRecord> steps = Steps();
  const SessionPlan plan = PlanWithSample();
  plan::PlanSummary summary;
  summary.step_count = 3;
  v1::Prompt prompt;
  prompt.set_step_index(2);
  SessionFacts facts(rec);
  facts.live_state = SessionState::kPaused;
  facts.live_reason = "paused (deferred) by alice";
  facts.plan = &plan;
  facts.with_plan = true;
  facts.steps = &steps;
  facts.summary = &summary;
  facts.eta_s = 12.5;
  facts.pending_prompt = &prompt;
  facts.last_quality_code = 0;
  v1::Session s = ToProtoSession(facts);

  EXPECT_EQ(s.state(), v1::SESSION_STATE_PAUSED);
  EXPECT_EQ(s.state_reason(), "paused (deferred) by alice");
  EXPECT_TRUE(s.end_reason().empty());
  EXPECT_EQ(s.plan().name(), "red paint");
  EXPECT_EQ(s.summary().step_count(), 3U);
  EXPECT_EQ(s.eta_s(), 12.5);
  EXPECT_EQ(s.current_step(), 2);
  EXPECT_EQ(s.last_quality_code(), 0);
  EXPECT_FALSE(s.has_pending_prompt()) << "a prompt shows only while awaiting the operator";

  facts.live_state = SessionState::kAwaitingOperator;
  s = ToProtoSession(facts);
  EXPECT_EQ(s.pending_prompt().step_index(), 2);
  EXPECT_TRUE(s.state_reason().empty()) << "no reason shown while awaiting the operator";

  facts.live_reason.clear();
  facts.live_state = SessionState::kPaused;
  EXPECT_EQ(ToProtoSession(facts).state_reason(), "stored reason")
      << "without a live reason, the record's";
}

TEST(WireSessionTest, AQueuedSessionThatNeverStartedHasNoCurrentStepAndAPlanThatDoesNotParseNone) {
  const storage::SessionRecord rec = Record(SessionState::kQueued);
  const std::vector<storage::StepRecord> steps = Steps();
  SessionFacts facts(rec);
  facts.steps = &steps;
  facts.with_plan = true;  // but no plan: it did not parse
  const v1::Session s = ToProtoSession(facts);
  EXPECT_EQ(s.current_step(), -1);
  EXPECT_FALSE(s.has_plan());
  EXPECT_FALSE(s.has_sample());
  EXPECT_EQ(s.state_reason(), "stored reason");
}

TEST(WireEnumsTest, EverySessionStateGoesToTheApiAndBack) {
  for (SessionState state :
       {SessionState::kQueued, SessionState::kRunning, SessionState::kPausing,
        SessionState::kPaused, SessionState::kAwaitingOperator, SessionState::kCompleted,
        SessionState::kAborted, SessionState::kFailed}) {
    const v1::SessionState wire = ToProtoState(state);
    EXPECT_NE(wire, v1::SESSION_STATE_UNSPECIFIED);
    EXPECT_EQ(FromProtoState(wire), state) << v1::SessionState_Name(wire);
  }
}

TEST(WireEnumsTest, UnspecifiedReadsAsTheDefaultAndUnknownAsNone) {
  EXPECT_EQ(FromProtoQuantity(v1::QUANTITY_UNSPECIFIED), Quantity::kBrdf);
  EXPECT_EQ(FromProtoQuantity(v1::QUANTITY_RADIANCE), Quantity::kRadiance);
  EXPECT_FALSE(FromProtoQuantity(99).has_value());
  EXPECT_EQ(FromProtoMethod(v1::INTERPOLATION_METHOD_UNSPECIFIED), interp::Method::kOctant);
  EXPECT_FALSE(FromProtoMethod(-1).has_value());
  EXPECT_EQ(FromProtoPauseMode(v1::PAUSE_MODE_UNSPECIFIED), PauseMode::kDeferred);
  EXPECT_EQ(FromProtoPauseMode(v1::PAUSE_MODE_IMMEDIATE), PauseMode::kImmediate);
  EXPECT_FALSE(FromProtoPauseMode(7).has_value());
  EXPECT_FALSE(FromProtoReadingKind(v1::READING_KIND_UNSPECIFIED).has_value());
  for (ReadingKind kind : {ReadingKind::kSample, ReadingKind::kReference, ReadingKind::kDark}) {
    EXPECT_EQ(FromProtoReadingKind(ToProtoReadingKind(kind)), kind);
  }
  for (interp::Method method :
       {interp::Method::kOctant, interp::Method::kDelaunay, interp::Method::kNearest}) {
    EXPECT_EQ(FromProtoMethod(ToProtoMethod(method)), method);
  }
  for (Quantity q : {Quantity::kRadiance, Quantity::kReflectance, Quantity::kBrdf}) {
    EXPECT_EQ(FromProtoQuantity(ToProtoQuantity(q)), q);
  }
}

TEST(WireEnumsTest, StepAndPromptKindsGoToStorageAndBack) {
  for (storage::StepKind kind :
       {storage::StepKind::kMove, storage::StepKind::kPrompt, storage::StepKind::kReference,
        storage::StepKind::kDark, storage::StepKind::kSample}) {
    EXPECT_EQ(ToStorageKind(ToProtoKind(kind)), kind);
  }
  EXPECT_EQ(PromptKindWord(v1::PROMPT_KIND_RELOCATE_DETECTOR), "relocate_detector");
  EXPECT_EQ(ParsePromptKindWord("relocate_detector"), v1::PROMPT_KIND_RELOCATE_DETECTOR);
  EXPECT_EQ(ParsePromptKindWord("no such word"), v1::PROMPT_KIND_UNSPECIFIED);
}

}  // namespace
}  // namespace brdf::daemon
