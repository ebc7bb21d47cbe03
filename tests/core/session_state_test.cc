#include "core/session_state.h"

#include <gtest/gtest.h>

namespace brdf {
namespace {

using S = SessionState;
using E = SessionEvent;

constexpr S kAllStates[] = {S::kQueued,           S::kRunning,   S::kPausing, S::kPaused,
                            S::kAwaitingOperator, S::kCompleted, S::kAborted, S::kFailed};
constexpr E kAllEvents[] = {E::kStart, E::kPauseDeferred, E::kPauseImmediate, E::kResume,
                            E::kAbort, E::kAnswer,        E::kPrompt,         E::kStepDone,
                            E::kFault, E::kFinish,        E::kError};

S Next(S from, E e, bool rig_free = true) {
  auto r = NextState(from, e, rig_free);
  EXPECT_TRUE(r.ok()) << SessionStateName(from) << " x " << SessionEventName(e) << ": "
                      << r.status().ToString();
  return r.ok() ? *r : from;
}

TEST(SessionStateTest, HappyPathRunsToCompletion) {
  S s = Next(S::kQueued, E::kStart);
  EXPECT_EQ(s, S::kRunning);
  s = Next(s, E::kPrompt);
  EXPECT_EQ(s, S::kAwaitingOperator);
  s = Next(s, E::kAnswer);
  EXPECT_EQ(s, S::kRunning);
  s = Next(s, E::kStepDone);
  EXPECT_EQ(Next(s, E::kFinish), S::kCompleted);
}

TEST(SessionStateTest, DeferredPauseTakesEffectWhenTheStepIsDone) {
  S s = Next(S::kRunning, E::kPauseDeferred);
  EXPECT_EQ(s, S::kPausing);
  EXPECT_EQ(Next(s, E::kStepDone), S::kPaused);
  EXPECT_EQ(Next(s, E::kPauseImmediate), S::kPaused);  // upgrade
  EXPECT_EQ(Next(s, E::kResume), S::kRunning);         // changed their mind in time
}

TEST(SessionStateTest, FaultPausesAndResumeRetries) {
  EXPECT_EQ(Next(S::kRunning, E::kFault), S::kPaused);
  EXPECT_EQ(Next(S::kAwaitingOperator, E::kFault), S::kPaused);
  EXPECT_EQ(Next(S::kPaused, E::kResume), S::kRunning);
}

TEST(SessionStateTest, StartAndResumeQueueWhenTheRigIsBusy) {
  EXPECT_EQ(Next(S::kQueued, E::kStart, /*rig_free=*/false), S::kQueued);
  EXPECT_EQ(Next(S::kPaused, E::kResume, /*rig_free=*/false), S::kQueued);
}

TEST(SessionStateTest, AbortFromEveryLiveStateAndNothingFromTerminalStates) {
  for (S s : kAllStates) {
    if (IsTerminal(s)) {
      for (E e : kAllEvents) {
        auto r = NextState(s, e);
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.status().code(), StatusCode::kFailedPrecondition);
        EXPECT_NE(r.status().message().find(SessionStateName(s)), std::string::npos);
      }
    } else {
      EXPECT_EQ(Next(s, E::kAbort), S::kAborted);
      EXPECT_EQ(Next(s, E::kError), S::kFailed);
    }
  }
}

TEST(SessionStateTest, RefusalsNameStateAndVerb) {
  auto r = NextState(S::kRunning, E::kResume);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "cannot resume a session that is running");
  EXPECT_FALSE(NextState(S::kQueued, E::kAnswer).ok());
  EXPECT_FALSE(NextState(S::kPaused, E::kAnswer).ok());
}

TEST(SessionStateTest, NamesRoundTrip) {
  for (S s : kAllStates) {
    auto parsed = ParseSessionState(SessionStateName(s));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, s);
  }
  EXPECT_FALSE(ParseSessionState("runing").ok());
}

}  // namespace
}  // namespace brdf
