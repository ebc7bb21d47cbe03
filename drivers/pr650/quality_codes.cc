#include "drivers/pr650/quality_codes.h"

#include <algorithm>
#include <array>

namespace brdf::drivers::pr650 {

namespace {

constexpr std::array<QualityCodeInfo, 20> kTable = {{
    {0, "OK", ""},
    {1, "no EOS signal at start of measurement", "power-cycle the meter; if it persists, service"},
    {3, "no start signal", "power-cycle the meter; if it persists, service"},
    {4, "no EOS signal to start integration time",
     "power-cycle the meter; if it persists, service"},
    {5, "DMA failure", "power-cycle the meter; if it persists, service"},
    {6, "no EOS after changing to sync mode", "switch sync off or power-cycle the meter"},
    {7, "unable to sync to light source", "switch sync off for this lamp"},
    {8, "sync lost during measurement", "switch sync off for this lamp"},
    {10, "weak light signal", "use a longer integration time or more light"},
    {12, "unspecified hardware malfunction", "power-cycle the meter; if it persists, service"},
    {13, "software error", "power-cycle the meter"},
    {14, "no sample in L*u*v*/L*a*b* calculation", "check the meter's colour setup"},
    {16, "adaptive integration taking too long (variable source?)",
     "use a fixed integration time or a steadier lamp"},
    {17, "main battery low", "charge or replace the meter's battery"},
    {18, "low light level", "data usable; a longer integration time improves it"},
    {19, "light level too high (overload)", "use a shorter integration time or less light"},
    {20, "no sync signal", "check the sync source, or switch sync off"},
    {21, "RAM error", "power-cycle the meter; if it persists, service"},
    {29, "corrupted data", "retry; check the cable if it persists"},
    {30, "noisy signal", "check the lamp's stability"},
}};

QualityDecision Exhausted(const QualityRule& rule, int code, const std::string& why) {
  QualityDecision d;
  if (rule.accept_flagged_when_exhausted || rule.action == QualityAction::kRetryThenFlag) {
    d.kind = QualityDecision::Kind::kAcceptFlagged;
    d.note = "quality " + DescribeQualityCode(code) + ": " + why + "; accepted, flagged";
  } else {
    d.kind = QualityDecision::Kind::kFail;
    d.note = "quality " + DescribeQualityCode(code) + ": " + why;
  }
  return d;
}

QualityDecision Remeasure(int integration_ms, bool sync, std::string note) {
  QualityDecision d;
  d.kind = QualityDecision::Kind::kRemeasure;
  d.new_integration_ms = integration_ms;
  d.new_sync = sync;
  d.note = std::move(note);
  return d;
}

}  // namespace

const QualityCodeInfo* FindQualityCode(int code) {
  for (const QualityCodeInfo& info : kTable) {
    if (info.code == code) return &info;
  }
  return nullptr;
}

std::string DescribeQualityCode(int code) {
  const QualityCodeInfo* info = FindQualityCode(code);
  std::string digits = std::to_string(code);
  if (digits.size() < 2) digits.insert(0, "0");
  return digits + " (" + (info ? info->meaning : "unknown quality code") + ")";
}

std::optional<QualityAction> ParseQualityAction(std::string_view name) {
  static constexpr std::pair<std::string_view, QualityAction> kNames[] = {
      {"accept", QualityAction::kAccept},
      {"accept_and_flag", QualityAction::kAcceptAndFlag},
      {"retry", QualityAction::kRetry},
      {"retry_then_flag", QualityAction::kRetryThenFlag},
      {"adapt_integration", QualityAction::kAdaptIntegration},
      {"sync_off_and_retry", QualityAction::kSyncOffAndRetry},
      {"fail", QualityAction::kFail},
  };
  for (const auto& [n, a] : kNames) {
    if (n == name) return a;
  }
  return std::nullopt;
}

const char* QualityActionName(QualityAction action) {
  switch (action) {
    case QualityAction::kAccept:
      return "accept";
    case QualityAction::kAcceptAndFlag:
      return "accept_and_flag";
    case QualityAction::kRetry:
      return "retry";
    case QualityAction::kRetryThenFlag:
      return "retry_then_flag";
    case QualityAction::kAdaptIntegration:
      return "adapt_integration";
    case QualityAction::kSyncOffAndRetry:
      return "sync_off_and_retry";
    case QualityAction::kFail:
      return "fail";
  }
  return "unknown";
}

QualityPolicy QualityPolicy::Defaults() {
  QualityPolicy p;
  for (const QualityCodeInfo& info : kTable) p.rules_[info.code] = {QualityAction::kFail, false};
  p.rules_[0] = {QualityAction::kAccept, false};
  p.rules_[7] = {QualityAction::kSyncOffAndRetry, false};
  p.rules_[8] = {QualityAction::kSyncOffAndRetry, false};
  p.rules_[10] = {QualityAction::kAdaptIntegration, false};  // "or record as unusable"
  p.rules_[16] = {QualityAction::kRetry, false};
  p.rules_[18] = {QualityAction::kAcceptAndFlag, true};
  p.rules_[19] = {QualityAction::kAdaptIntegration, false};
  p.rules_[29] = {QualityAction::kRetry, false};
  p.rules_[30] = {QualityAction::kRetryThenFlag, true};
  return p;
}

QualityRule QualityPolicy::RuleFor(int code) const {
  const auto it = rules_.find(code);
  return it == rules_.end() ? unknown_ : it->second;
}

bool IsLowLightCode(int code) {
  return code == 10 || code == 18;
}

QualityDecision DecideQuality(const QualityPolicy& policy, int code, const MeasureLoopState& s) {
  const QualityRule rule = policy.RuleFor(code);
  const std::string what = "quality " + DescribeQualityCode(code);
  if (s.low_light_expected && IsLowLightCode(code)) {
    QualityDecision d;
    d.kind = QualityDecision::Kind::kAccept;
    d.note = what + ": expected for a dark reading, accepted";
    return d;
  }
  const bool attempts_left = s.attempt < s.max_attempts;
  const std::string used_up = "still failing after " + std::to_string(s.attempt) + " attempt(s)";

  switch (rule.action) {
    case QualityAction::kAccept: {
      QualityDecision d;
      d.kind = QualityDecision::Kind::kAccept;
      if (code != 0) d.note = what + ": accepted by policy";
      return d;
    }
    case QualityAction::kAcceptAndFlag: {
      QualityDecision d;
      d.kind = QualityDecision::Kind::kAcceptFlagged;
      d.note = what + ": accepted, flagged";
      return d;
    }
    case QualityAction::kRetry:
    case QualityAction::kRetryThenFlag:
      if (!attempts_left) return Exhausted(rule, code, used_up);
      return Remeasure(s.integration_ms, s.sync, what + ": measuring again");
    case QualityAction::kSyncOffAndRetry:
      if (!attempts_left) return Exhausted(rule, code, used_up);
      return Remeasure(s.integration_ms, false,
                       what + (s.sync ? ": sync switched off, measuring again"
                                      : ": sync already off, measuring again"));
    case QualityAction::kAdaptIntegration: {
      if (!attempts_left) return Exhausted(rule, code, used_up);
      if (s.integration_ms == 0) {
        return Exhausted(rule, code,
                         "the integration time is adaptive, so it cannot be halved or doubled "
                         "(configure a fixed integration time to let the driver adapt it)");
      }
      // 19 (overload) asks for less light per measurement; every other code this action is set
      // for (10 weak signal, 18 low light) asks for more.
      if (code == 19) {
        if (s.integration_ms <= kMinIntegrationMs) {
          return Exhausted(
              rule, code,
              "integration already at the " + std::to_string(kMinIntegrationMs) + " ms minimum");
        }
        const int halved = std::max(kMinIntegrationMs, s.integration_ms / 2);
        return Remeasure(halved, s.sync,
                         what + ": integration halved from " + std::to_string(s.integration_ms) +
                             " to " + std::to_string(halved) + " ms");
      }
      if (s.integration_ms >= kMaxIntegrationMs) {
        return Exhausted(
            rule, code,
            "integration already at the " + std::to_string(kMaxIntegrationMs) + " ms maximum");
      }
      const int doubled = std::min(kMaxIntegrationMs, s.integration_ms * 2);
      return Remeasure(doubled, s.sync,
                       what + ": integration doubled from " + std::to_string(s.integration_ms) +
                           " to " + std::to_string(doubled) + " ms");
    }
    case QualityAction::kFail:
      break;
  }
  QualityDecision d;
  d.kind = QualityDecision::Kind::kFail;
  d.note = what;
  return d;
}

}  // namespace brdf::drivers::pr650
