#include "drivers/pr650/quality_loop.h"

namespace brdf::drivers::pr650 {

QualityLoop::QualityLoop(const QualityPolicy& policy, int max_attempts, bool dark,
                         serial::LogSink log, std::string where)
    : policy_(policy),
      max_attempts_(max_attempts),
      dark_(dark),
      log_(std::move(log)),
      where_(std::move(where)) {}

QualityDecision QualityLoop::Judge(int meter_code, const std::string& meaning, int policy_code,
                                   int integration_ms, bool sync) {
  const MeasureLoopState state{integration_ms, sync, attempt_, max_attempts_, dark_};
  QualityDecision decision = DecideQuality(policy_, policy_code, state);
  if (meter_code != 0 || !decision.note.empty()) {
    // The meter's own words first; the policy's (in the PR-650's numbering) after.
    std::string note = "code " + std::to_string(meter_code) + " (" + meaning + ")";
    if (policy_code != meter_code || decision.note.empty()) {
      note += ", handled as " +
              (decision.note.empty() ? DescribeQualityCode(policy_code) : decision.note);
    } else {
      note += ": " + decision.note;
    }
    decision.note = note;
    notes_.push_back(note);
    log_("measurement " + std::to_string(attempt_) + " on " + where_ + ": " + note);
  }
  return decision;
}

bool QualityLoop::Accepted(const QualityDecision& decision) {
  return decision.kind == QualityDecision::Kind::kAccept ||
         decision.kind == QualityDecision::Kind::kAcceptFlagged;
}

MeasurementOutcome QualityLoop::Outcome(int meter_code, const QualityDecision& decision,
                                        int integration_ms) const {
  MeasurementOutcome outcome;
  outcome.quality_code = meter_code;
  outcome.flagged = decision.kind == QualityDecision::Kind::kAcceptFlagged;
  outcome.integration_ms = integration_ms;
  outcome.attempts = attempt_;
  outcome.note = notes();
  return outcome;
}

Status QualityLoop::Failure(int meter_code, const std::string& hint) const {
  return DeviceError(meter_code, where_ + ": measurement failed after " + std::to_string(attempt_) +
                                     " attempt(s): " + notes() + "; " + hint);
}

std::string QualityLoop::notes() const {
  std::string out;
  for (const std::string& n : notes_) {
    if (n.empty()) continue;
    if (!out.empty()) out += "; ";
    out += n;
  }
  return out;
}

}  // namespace brdf::drivers::pr650
