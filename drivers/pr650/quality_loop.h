// The quality policy's bookkeeping over one Measure call, for the meters whose own codes map onto
// the policy's (the PR-670's result codes, the CS-2000's ERxx replies; quality_codes.h): which
// attempt this is, what was decided and why (the notes a reading carries), and the outcome once
// a code is accepted. The driver measures, asks Judge, and carries the decision out.
#pragma once

#include <string>
#include <vector>

#include "drivers/pr650/quality_codes.h"
#include "drivers/serial/serial_link.h"
#include "drivers/spectroradiometer.h"

namespace brdf::drivers::pr650 {

class QualityLoop {
 public:
  // `dark`: the reading is a dark one (MeasurementSettings::dark); `where` names the meter and its
  // port in the log ("PR-670 on /dev/ttyACM0").
  QualityLoop(const QualityPolicy& policy, int max_attempts, bool dark, serial::LogSink log,
              std::string where);

  // Decides about the meter's `meter_code` (its words: `meaning`), handled as `policy_code`,
  // for the current attempt with the current integration (0 adaptive) and sync; notes and logs
  // what was decided.
  QualityDecision Judge(int meter_code, const std::string& meaning, int policy_code,
                        int integration_ms, bool sync);
  static bool Accepted(const QualityDecision& decision);

  // The accepted measurement: the meter's own code, flagged or not, the attempts and the notes.
  MeasurementOutcome Outcome(int meter_code, const QualityDecision& decision,
                             int integration_ms) const;
  // kDeviceError (device_code = the meter's code) for a decision to fail, with `hint`.
  Status Failure(int meter_code, const std::string& hint) const;

  int attempt() const { return attempt_; }
  void NextAttempt() { ++attempt_; }
  // What was decided so far, "; "-separated.
  std::string notes() const;
  // Adds a note of the driver's own (e.g. a report in other units than radiance).
  void Note(const std::string& note) { notes_.push_back(note); }

 private:
  const QualityPolicy& policy_;
  int max_attempts_;
  bool dark_;
  serial::LogSink log_;
  std::string where_;
  int attempt_ = 1;
  std::vector<std::string> notes_;
};

}  // namespace brdf::drivers::pr650
