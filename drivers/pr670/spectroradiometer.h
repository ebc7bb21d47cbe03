// The PR-655 and PR-670 SpectraScan behind the Spectroradiometer interface
// (docs/pr670-protocol.md).
//
// Connect opens the port (exclusively), sends Q (no line end; a meter still in remote mode from an
// earlier program leaves it, so the next PHOTO is answered), waits quit_settle, types PHOTO a
// character at a time and waits up to remote_timeout for the meter's answer, whatever its text:
// the meter is then in remote mode. Disconnect sends Q and closes the port.
//
// Every command is typed a character at a time (char_gap apart) and ended by CR. Identify reads
// D111 (the instrument's name, "PR-670"), D110 (its serial number) and D120 (its wavelength
// layout: 201 bands from 380 nm every 2 nm on a PR-670, 101 every 4 nm on a PR-655).
//
// A measurement is M5: the meter measures and answers with report 5 (a header and one line per
// band), or with its result code alone when the measurement failed. The code goes through the
// quality policy as the PR-650 code with the same handling (pr670::PolicyCodeFor): -8 (too dark)
// as 10 (a longer fixed exposure; a dark reading accepts it, recorded as zeros, for the meter
// sends no spectrum), -1 and -10 (sync failure) as 07 (SS0 and measure again). Measure keeps the
// spectrum it received; TransferSpectrum hands it over.
//
// Errors: kTimeout (silence; the rig then connects again, which re-enters remote mode),
// kCancelled, kDeviceError (device_code = the meter's result code), kProtocolError,
// kDisconnected (port vanished), kConfigurationError (options), kInvalidArgument (settings the
// meter cannot take), kFailedPrecondition (not connected, nothing measured).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "drivers/line_meter/connection.h"
#include "drivers/pr650/quality_loop.h"
#include "drivers/pr670/options.h"
#include "drivers/pr670/protocol.h"
#include "drivers/spectroradiometer.h"

namespace brdf::drivers {

class Pr670Spectroradiometer final : public Spectroradiometer {
 public:
  explicit Pr670Spectroradiometer(
      Pr670Options options,
      serial::CommandChannel::LinkFactory link_factory = serial::MakeSerialLink);
  ~Pr670Spectroradiometer() override;

  Status Connect(const CallContext& ctx) override;
  void Disconnect() override;
  bool connected() const override { return connection_.connected(); }

  Result<MeterIdentity> Identify(const CallContext& ctx) override;
  Status Configure(const MeasurementSettings& settings, const CallContext& ctx) override;
  Result<MeasurementOutcome> Measure(const CallContext& ctx) override;
  Result<SpectrumReport> TransferSpectrum(const CallContext& ctx) override;
  // One M5 per attempt; `measured` runs as the report's header line is accepted.
  Result<MeasuredSpectrum> MeasureSpectrum(const CallContext& ctx,
                                           const MeasuredCallback& measured) override;

  const Pr670Options& options() const { return options_; }

 private:
  // What the meter was last set to (SE, SN, SS).
  struct Setup {
    int exposure_ms = 0;
    int averages = 1;
    bool sync = false;
    friend bool operator==(const Setup&, const Setup&) = default;
  };

  Status EnterRemoteMode(const CallContext& ctx);
  // Sends one command and reads a one-line reply; notes a vanished port.
  Result<std::string> Ask(std::string_view command, std::chrono::milliseconds timeout,
                          const CallContext& ctx);
  // S-command: "0000" accepted, any other code a kDeviceError.
  Status SetOne(const std::string& command, const CallContext& ctx);
  Status Apply(const Setup& setup, const CallContext& ctx);
  Result<MeasuredSpectrum> MeasureLoop(const CallContext& ctx, const MeasuredCallback& measured);
  // One M5: the reply, with `on_header` seeing its first line as it arrives.
  Result<std::string> MeasureOnce(const CallContext& ctx,
                                  const std::function<void(std::string_view)>& on_header);
  // A rejected code: fail, or change the exposure/sync for the next attempt.
  Status PrepareRemeasure(const pr650::QualityDecision& decision, int code,
                          pr650::QualityLoop& loop, const CallContext& ctx);
  // The accepted report: the parsed spectrum, or zeros for an accepted code without data.
  Result<SpectrumReport> ReportFrom(const std::string& reply, int code,
                                    pr650::QualityLoop& loop) const;
  Status Lost(const Status& status);

  Pr670Options options_;
  LineMeterConnection connection_;

  std::optional<Setup> configured_;   // what Configure asked for
  std::optional<Setup> meter_setup_;  // what the meter was last set to
  bool dark_ = false;
  WavelengthGrid grid_{380, 2, 201};    // the PR-670's, until D120 tells
  std::optional<SpectrumReport> held_;  // the last accepted measurement's spectrum
};

}  // namespace brdf::drivers
