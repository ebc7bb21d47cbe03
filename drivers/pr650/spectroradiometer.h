// The PR-650 SpectraScan behind the Spectroradiometer interface. Other meters (PR-655/670: PHOTO
// to enter remote mode, CR-terminated commands, M5 for the spectrum) would be sibling classes
// over the same SerialLink seam.
//
// Connect opens the port, drops RTS (> 50 ms, by close and reopen), waits for the meter to settle
// and sends B<n> until it answers "000" (bounded attempts). A silent meter is kTimeout with the
// operator's remedy: power-cycle it and connect within 5 s; XFER/CTRLR on CTRLR.
//
// Every exchange: wait out the pacing, empty the input buffer, write the command + LF, read the
// reply (drivers/serial/reply_reader.h), parse it (protocol.h). If a call is cancelled or times
// out while the meter may still answer (an M0 takes up to 30 s), the next exchange first waits
// for and discards that late reply, so it is never mistaken for the answer to a new command.
//
// M0 reply: the sources give only "000" for success. This driver reads it as a 3-digit status
// whose value is the quality code ("018" = low light), and judges the report's own quality code
// (the D5/M5 status line) too, so a meter that answers M0 with 000 cannot hide low light or
// overload. A "-1" in place of a status or report means the meter holds no measurement:
// kDeviceError with device code -1, which the caller may measure again.
//
// A measurement's reply (M0, M5) may take averages × integration time (adaptive: 6,000 ms) plus
// measurement_timeout as a margin (MeasurementReplyTimeout). A spectrum in other units than
// radiance (units code 1 irradiance, 2 uncalibrated) is returned flagged, with a note.
//
// Errors: kTimeout, kCancelled, kDeviceError (device_code = quality code, or the S reply's bad
// field position / 50), kProtocolError, kDisconnected (port vanished: Connect again once it is
// back), kConfigurationError (options, port name), kInvalidArgument (settings),
// kFailedPrecondition (not connected, nothing measured).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/pr650/options.h"
#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_reader.h"
#include "drivers/serial/serial_link.h"
#include "drivers/spectroradiometer.h"

namespace brdf::drivers {

class Pr650Spectroradiometer final : public Spectroradiometer {
 public:
  // Makes the (closed) link for a port; tests may hand in their own transport.
  using LinkFactory = std::function<Result<std::unique_ptr<serial::SerialLink>>(
      const serial::SerialSettings&, serial::LogSink)>;

  explicit Pr650Spectroradiometer(Pr650Options options,
                                  LinkFactory link_factory = serial::MakeSerialLink);
  ~Pr650Spectroradiometer() override;

  Status Connect(const CallContext& ctx) override;
  void Disconnect() override;
  bool connected() const override { return connected_; }

  Result<MeterIdentity> Identify(const CallContext& ctx) override;
  Status Configure(const MeasurementSettings& settings, const CallContext& ctx) override;
  Result<MeasurementOutcome> Measure(const CallContext& ctx) override;
  Result<SpectrumReport> TransferSpectrum(const CallContext& ctx) override;
  // With options().measure_with_spectrum: one M5 exchange per attempt (the D5 report follows the
  // measurement in its reply); `measured` runs when the report's status line is accepted.
  // Otherwise M0 then D5, as Measure and TransferSpectrum.
  Result<MeasuredSpectrum> MeasureSpectrum(const CallContext& ctx,
                                           const MeasuredCallback& measured) override;

  const Pr650Options& options() const { return options_; }

 private:
  using Duration = std::chrono::steady_clock::duration;

  Status OpenWithRtsDrop(const CallContext& ctx);
  Status Wake(const CallContext& ctx);
  Status RequireConnected() const;
  using FirstLine = std::function<void(std::string_view)>;
  // Sends `command` and reads a reply of `lines` lines, the first byte within `timeout`;
  // `first_line` (if set) sees the reply's first line as soon as it is complete.
  Result<std::string> Exchange(std::string_view command, std::size_t lines, Duration timeout,
                               const CallContext& ctx, const FirstLine& first_line = {});
  Status DiscardLateReply(const CallContext& ctx);
  Status SendSetup(const pr650::SetupFields& fields, const CallContext& ctx);
  pr650::SetupFields CurrentSetup() const;

  // The measurement loop shared by Measure and MeasureSpectrum. StartMeasuring restores the
  // configured setup; Judge applies the quality policy to attempt `attempt`'s code (logging its
  // note); an accepted code becomes Outcome; otherwise PrepareRemeasure fails (kDeviceError) or
  // changes the setup as the policy asks before the next attempt.
  Status StartMeasuring(const CallContext& ctx);
  // One M0: the status the meter answers (the quality code), or kDeviceError -1 (no data).
  Result<int> MeasureAndHold(const CallContext& ctx);
  // The first-byte timeout of a measurement's reply with the current setup.
  std::chrono::milliseconds MeasurementTimeout() const;
  // kDeviceError -1: the meter answered `command` with "-1".
  Status NoMeasurement(std::string_view command) const;
  // A measurement's timeout with what it was made of and what the operator can do.
  Status WithMeasurementHint(const Status& status, const CallContext& ctx) const;
  // Flags `outcome` (with a note) when the report is not spectral radiance (units code != 0).
  void FlagUnits(int units_code, MeasurementOutcome& outcome) const;
  pr650::QualityDecision Judge(int code, int attempt, std::vector<std::string>& notes) const;
  static bool Accepted(const pr650::QualityDecision& decision);
  MeasurementOutcome Outcome(int code, const pr650::QualityDecision& decision, int attempt,
                             const std::vector<std::string>& notes) const;
  Status PrepareRemeasure(int code, const pr650::QualityDecision& decision, int attempt,
                          const std::vector<std::string>& notes, const CallContext& ctx);
  Result<SpectrumReport> SpectrumFromReply(std::string_view reply, std::string_view command) const;
  void DropLink();
  // A "did not answer" timeout with what the operator can check.
  Status WithSilenceHint(const Status& status, const CallContext& ctx) const;
  void Log(const std::string& message) const;

  Pr650Options options_;
  LinkFactory link_factory_;
  serial::FramingOptions framing_;

  std::unique_ptr<serial::SerialLink> link_;
  bool connected_ = false;
  bool port_seen_ = false;        // the port has opened before: a missing port has vanished
  bool lost_connection_ = false;  // the link went down under us (vs never connected)

  std::optional<pr650::SetupFields> configured_;  // what Configure asked for
  bool dark_ = false;  // Configure's MeasurementSettings::dark: weak light is expected
  std::optional<pr650::SetupFields> meter_setup_;  // what the meter was last set to (S accepted)
  WavelengthGrid grid_ = WavelengthGrid::Pr650();  // from D120 once identified
  bool holds_measurement_ = false;

  std::chrono::steady_clock::time_point next_command_at_{};
  std::optional<std::chrono::steady_clock::time_point> late_reply_until_;
};

}  // namespace brdf::drivers
