// A spectroradiometer, as the daemon sees it: connect, identify, configure, measure, transfer.
// The daemon moves the stage while the (slow, 9600-baud) spectrum transfer streams: MeasureSpectrum
// tells it when the measurement is done and the transfer begins. Knows nothing of plans, poses or
// storage.
//
// Threading: one instance is used by one thread at a time (the daemon's meter worker). Every call
// takes a CallContext; it returns kTimeout at the deadline and kCancelled when cancelled, and never
// blocks past either.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::drivers {

struct MeterIdentity {
  std::string model;          // "PR-650"
  std::string serial_number;  // as reported by the meter (D110), trimmed
  WavelengthGrid grid;        // as reported by the meter (D120)
};

struct MeasurementSettings {
  int integration_ms = 0;       // 0 = adaptive (the meter chooses), else 10–6000 ms
  int averages = 1;             // 1–99 measurements averaged by the meter
  bool sync_to_source = false;  // sync integration to the lamp's flicker (uses F)
  // A dark reading (shutter closed): weak-light quality codes are expected and accepted as they
  // are, not adapted or failed (a PR-650 reports 10 or 18 on a dark).
  bool dark = false;
};

// What happened during one measurement (the meter holds the data until transferred).
struct MeasurementOutcome {
  int quality_code = 0;    // the meter's final quality code (0 = OK)
  bool flagged = false;    // usable but flagged by the quality policy (e.g. 18 low light)
  int integration_ms = 0;  // integration actually used (after any adaptation); 0 = adaptive
  int attempts = 1;        // measurements taken, including policy retries
  std::string note;        // what the policy did, for the log and the reading ("halved to 250 ms")
};

struct SpectrumReport {
  WavelengthGrid grid;
  std::vector<double> radiance;  // W·m⁻²·sr⁻¹·nm⁻¹ when units_code == 0
  int quality_code = 0;
  int units_code = 0;     // 0 radiance, 1 irradiance, 2 uncalibrated
  double integrated = 0;  // the meter's integrated intensity line
};

// One accepted measurement and its spectrum.
struct MeasuredSpectrum {
  MeasurementOutcome outcome;
  SpectrumReport report;
};

// Called once the measurement is final and accepted, before its spectrum has been transferred.
using MeasuredCallback = std::function<void(const MeasurementOutcome&)>;

class Spectroradiometer {
 public:
  virtual ~Spectroradiometer() = default;

  // Opens the link and brings the meter into remote mode. Idempotent when connected.
  virtual Status Connect(const CallContext& ctx) = 0;
  virtual void Disconnect() = 0;
  virtual bool connected() const = 0;

  virtual Result<MeterIdentity> Identify(const CallContext& ctx) = 0;
  virtual Status Configure(const MeasurementSettings& settings, const CallContext& ctx) = 0;

  // Takes one measurement and holds it in the meter, applying the quality policy (retry, adapt the
  // integration time, flag or fail). A code the policy fails on is a kDeviceError whose
  // device_code() is the quality code.
  virtual Result<MeasurementOutcome> Measure(const CallContext& ctx) = 0;

  // Transfers the spectrum of the last measurement.
  virtual Result<SpectrumReport> TransferSpectrum(const CallContext& ctx) = 0;

  // Measure and TransferSpectrum in one call, with `measured` (if set) called on this thread in
  // between: what has to wait only for the measurement, not its data (the stage's next move), can
  // start then. A meter that sends the spectrum in the measurement's own reply (the PR-650's M5)
  // overrides this to save an exchange; `measured` then runs as the reply's status line arrives.
  // If the transfer fails after `measured` ran, the error is returned all the same.
  virtual Result<MeasuredSpectrum> MeasureSpectrum(const CallContext& ctx,
                                                   const MeasuredCallback& measured);
};

}  // namespace brdf::drivers
