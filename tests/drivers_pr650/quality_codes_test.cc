// The quality-code table and the pure policy decisions.
#include "drivers/pr650/quality_codes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace brdf::drivers::pr650 {
namespace {

using ::testing::HasSubstr;
using Kind = QualityDecision::Kind;

constexpr int kReferenceCodes[] = {0,  1,  3,  4,  5,  6,  7,  8,  10, 12,
                                   13, 14, 16, 17, 18, 19, 20, 21, 29, 30};

MeasureLoopState State(int integration_ms, int attempt = 1, bool sync = false, int max = 4) {
  return MeasureLoopState{integration_ms, sync, attempt, max};
}

TEST(QualityTable, CoversEveryCodeInTheReference) {
  for (int code : kReferenceCodes) {
    const QualityCodeInfo* info = FindQualityCode(code);
    ASSERT_NE(info, nullptr) << code;
    EXPECT_EQ(info->code, code);
    EXPECT_STRNE(info->meaning, "");
  }
  EXPECT_EQ(FindQualityCode(2), nullptr);
  EXPECT_EQ(FindQualityCode(99), nullptr);
  EXPECT_EQ(DescribeQualityCode(19), "19 (light level too high (overload))");
  EXPECT_EQ(DescribeQualityCode(7), "07 (unable to sync to light source)");
  EXPECT_THAT(DescribeQualityCode(42), HasSubstr("unknown"));
}

TEST(QualityPolicy, DefaultsFollowWhatDriversDo) {
  const QualityPolicy p = QualityPolicy::Defaults();
  EXPECT_EQ(p.RuleFor(0).action, QualityAction::kAccept);
  EXPECT_EQ(p.RuleFor(7).action, QualityAction::kSyncOffAndRetry);
  EXPECT_EQ(p.RuleFor(8).action, QualityAction::kSyncOffAndRetry);
  EXPECT_EQ(p.RuleFor(10).action, QualityAction::kAdaptIntegration);
  EXPECT_EQ(p.RuleFor(16).action, QualityAction::kRetry);
  EXPECT_EQ(p.RuleFor(18).action, QualityAction::kAcceptAndFlag);
  EXPECT_EQ(p.RuleFor(19).action, QualityAction::kAdaptIntegration);
  EXPECT_EQ(p.RuleFor(29).action, QualityAction::kRetry);
  EXPECT_EQ(p.RuleFor(30).action, QualityAction::kRetryThenFlag);
  for (int code : {1, 3, 4, 5, 6, 12, 13, 14, 17, 20, 21}) {
    EXPECT_EQ(p.RuleFor(code).action, QualityAction::kFail) << code;
  }
  EXPECT_EQ(p.RuleFor(42).action, QualityAction::kFail);
}

TEST(DecideQuality, EveryCodeAndUnknownOnesGetADecisionWithoutCrashing) {
  const QualityPolicy p = QualityPolicy::Defaults();
  for (int code = -5; code < 1000; ++code) {
    const QualityDecision d = DecideQuality(p, code, State(200));
    if (code == 0) {
      EXPECT_EQ(d.kind, Kind::kAccept);
    } else {
      EXPECT_FALSE(d.note.empty()) << code;
    }
  }
}

TEST(DecideQuality, OverloadHalvesDownToTenMilliseconds) {
  const QualityPolicy p = QualityPolicy::Defaults();
  QualityDecision d = DecideQuality(p, 19, State(400));
  EXPECT_EQ(d.kind, Kind::kRemeasure);
  EXPECT_EQ(d.new_integration_ms, 200);
  EXPECT_THAT(d.note, HasSubstr("halved from 400 to 200 ms"));
  EXPECT_EQ(DecideQuality(p, 19, State(15)).new_integration_ms, 10);  // not 7
  d = DecideQuality(p, 19, State(10));
  EXPECT_EQ(d.kind, Kind::kFail);
  EXPECT_THAT(d.note, HasSubstr("10 ms minimum"));
}

TEST(DecideQuality, WeakSignalDoublesUpToSixSeconds) {
  const QualityPolicy p = QualityPolicy::Defaults();
  QualityDecision d = DecideQuality(p, 10, State(1000));
  EXPECT_EQ(d.kind, Kind::kRemeasure);
  EXPECT_EQ(d.new_integration_ms, 2000);
  EXPECT_EQ(DecideQuality(p, 10, State(4000)).new_integration_ms, 6000);
  d = DecideQuality(p, 10, State(6000));
  EXPECT_EQ(d.kind, Kind::kFail);  // "record as unusable"
  EXPECT_THAT(d.note, HasSubstr("6000 ms maximum"));
}

TEST(DecideQuality, LowLightFlagsByDefaultAndCanAdapt) {
  QualityPolicy p = QualityPolicy::Defaults();
  QualityDecision d = DecideQuality(p, 18, State(500));
  EXPECT_EQ(d.kind, Kind::kAcceptFlagged);
  p.Set(18, {QualityAction::kAdaptIntegration, true});
  d = DecideQuality(p, 18, State(500));
  EXPECT_EQ(d.kind, Kind::kRemeasure);
  EXPECT_EQ(d.new_integration_ms, 1000);
  // At the limit, low light is still usable: flagged rather than failed.
  EXPECT_EQ(DecideQuality(p, 18, State(6000)).kind, Kind::kAcceptFlagged);
  EXPECT_EQ(DecideQuality(p, 18, State(500, 4)).kind, Kind::kAcceptFlagged);
}

TEST(DecideQuality, AdaptiveIntegrationCannotBeAdapted) {
  const QualityPolicy p = QualityPolicy::Defaults();
  const QualityDecision d = DecideQuality(p, 19, State(0));
  EXPECT_EQ(d.kind, Kind::kFail);
  EXPECT_THAT(d.note, HasSubstr("adaptive"));
}

TEST(DecideQuality, SyncOffAndRetry) {
  const QualityPolicy p = QualityPolicy::Defaults();
  QualityDecision d = DecideQuality(p, 7, State(100, 1, true));
  EXPECT_EQ(d.kind, Kind::kRemeasure);
  EXPECT_FALSE(d.new_sync);
  EXPECT_EQ(d.new_integration_ms, 100);
  EXPECT_THAT(d.note, HasSubstr("sync switched off"));
  d = DecideQuality(p, 8, State(100, 1, false));
  EXPECT_EQ(d.kind, Kind::kRemeasure);
  EXPECT_THAT(d.note, HasSubstr("already off"));
}

TEST(DecideQuality, RetriesAreBounded) {
  const QualityPolicy p = QualityPolicy::Defaults();
  EXPECT_EQ(DecideQuality(p, 29, State(100, 3, false, 4)).kind, Kind::kRemeasure);
  const QualityDecision last = DecideQuality(p, 29, State(100, 4, false, 4));
  EXPECT_EQ(last.kind, Kind::kFail);
  EXPECT_THAT(last.note, HasSubstr("4 attempt(s)"));
  // 30 noisy: retried, then accepted flagged.
  EXPECT_EQ(DecideQuality(p, 30, State(100, 1)).kind, Kind::kRemeasure);
  EXPECT_EQ(DecideQuality(p, 30, State(100, 4)).kind, Kind::kAcceptFlagged);
  // Adaptation is bounded by attempts too.
  EXPECT_EQ(DecideQuality(p, 19, State(400, 4)).kind, Kind::kFail);
}

TEST(DecideQuality, PolicyIsConfigurablePerCodeAndForUnknownCodes) {
  QualityPolicy p = QualityPolicy::Defaults();
  p.Set(1, {QualityAction::kRetry, false});
  EXPECT_EQ(DecideQuality(p, 1, State(100)).kind, Kind::kRemeasure);
  p.SetUnknown({QualityAction::kAcceptAndFlag, false});
  EXPECT_EQ(DecideQuality(p, 42, State(100)).kind, Kind::kAcceptFlagged);
  p.Set(0, {QualityAction::kAcceptAndFlag, false});
  EXPECT_EQ(DecideQuality(p, 0, State(100)).kind, Kind::kAcceptFlagged);
}

TEST(QualityActionNames, RoundTrip) {
  for (QualityAction a :
       {QualityAction::kAccept, QualityAction::kAcceptAndFlag, QualityAction::kRetry,
        QualityAction::kRetryThenFlag, QualityAction::kAdaptIntegration,
        QualityAction::kSyncOffAndRetry, QualityAction::kFail}) {
    EXPECT_EQ(ParseQualityAction(QualityActionName(a)), a);
  }
  EXPECT_FALSE(ParseQualityAction("ignore").has_value());
}

}  // namespace
}  // namespace brdf::drivers::pr650
