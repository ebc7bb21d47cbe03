// The PR-650's measurement quality codes and what the driver does about each one.
//
// The table covers every code in the reference (00 01 03 04 05 06 07 08 10 12 13 14 16 17 18 19 20
// 21 29 30); any other code is "unknown" and handled by a rule of its own, never by a crash (older
// drivers knew only 00/10/18 and died on the rest). The policy is data: the daemon can change the
// rule of any code from the configuration; the defaults follow the reference's "what drivers do".
//
// Pure: the policy decides from the code and the state of the measurement loop; the driver carries
// the decision out.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace brdf::drivers::pr650 {

struct QualityCodeInfo {
  int code;
  const char* meaning;  // "light level too high (overload)"
  const char* hint;     // what the operator can do, "" when the policy handles it
};

// The entry for `code`, or nullptr when the reference does not list it.
const QualityCodeInfo* FindQualityCode(int code);

// "19 (light level too high (overload))" or "42 (unknown quality code)".
std::string DescribeQualityCode(int code);

enum class QualityAction {
  kAccept,            // use the data
  kAcceptAndFlag,     // use the data, mark the reading as flagged
  kRetry,             // measure again unchanged
  kRetryThenFlag,     // measure again; when attempts run out, accept flagged (30 noisy signal)
  kAdaptIntegration,  // 19: halve the integration time; 10 and 18: double it; then measure again
  kSyncOffAndRetry,   // 07/08: switch sync off (S) and measure again
  kFail,              // give up: kDeviceError with the quality code
};

// Parses "accept", "accept_and_flag", "retry", "retry_then_flag", "adapt_integration",
// "sync_off_and_retry", "fail" (the names a configuration file uses).
std::optional<QualityAction> ParseQualityAction(std::string_view name);
const char* QualityActionName(QualityAction action);

struct QualityRule {
  QualityAction action = QualityAction::kFail;
  // When the action cannot go on (attempts used up, integration at its limit, adaptive
  // integration that cannot be halved or doubled): accept flagged instead of failing. True for
  // 18 (low light: usable) and 30 (noisy: usable, flagged).
  bool accept_flagged_when_exhausted = false;
};

class QualityPolicy {
 public:
  // The reference's "what drivers do": 00 accept; 07/08 sync off and retry; 10 adapt (longer),
  // unusable when it cannot; 16 and 29 retry; 18 accept and flag; 19 adapt (shorter); 30 retry,
  // then flag; every other listed code and every unknown code fails.
  static QualityPolicy Defaults();

  QualityRule RuleFor(int code) const;
  void Set(int code, QualityRule rule) { rules_[code] = rule; }
  void SetUnknown(QualityRule rule) { unknown_ = rule; }

 private:
  std::map<int, QualityRule> rules_;
  QualityRule unknown_;  // fail
};

// Integration limits of the PR-650 (ms) that adaptation stays within.
inline constexpr int kMinIntegrationMs = 10;
inline constexpr int kMaxIntegrationMs = 6000;

// Where the measurement loop stands when a quality code comes back.
struct MeasureLoopState {
  int integration_ms = 0;  // current setting, 0 = adaptive
  bool sync = false;       // sync to source currently on
  int attempt = 1;         // measurements taken so far in this Measure call (1-based)
  int max_attempts = 4;    // bound on measurements per Measure call
  // The measurement is a dark reading (shutter closed): weak light is what it is meant to see.
  // Weak-light codes (IsLowLightCode) are then accepted as they are, without adapting the
  // integration (a dark must keep the sample's integration to be subtracted from it) and without
  // a flag, whatever the policy says for light readings.
  bool low_light_expected = false;
};

// 10 (weak light signal) and 18 (low light level): the codes a dark reading is expected to earn.
bool IsLowLightCode(int code);

struct QualityDecision {
  enum class Kind {
    kAccept,         // done: the data are good
    kAcceptFlagged,  // done: the data are usable but flagged
    kRemeasure,      // measure again, after applying new_integration_ms / new_sync
    kFail,           // done: kDeviceError
  };
  Kind kind = Kind::kFail;
  int new_integration_ms = 0;  // kRemeasure: integration to set (equal to the current: unchanged)
  bool new_sync = false;       // kRemeasure: sync to set
  std::string note;            // what was decided and why, for the log and the reading
};

// Decides what to do about `code` under `policy` (and state.low_light_expected, above).
QualityDecision DecideQuality(const QualityPolicy& policy, int code, const MeasureLoopState& state);

}  // namespace brdf::drivers::pr650
