// The Konica Minolta CS-2000, CS-2000A and CS-3000 behind the Spectroradiometer interface
// (docs/cs2000-protocol.md).
//
// Connect opens the port (exclusively) and sends RMTS,1 (remote mode on) until the meter answers
// OK00; Disconnect sends RMTS,0 and closes the port. Identify reads IDDR (model and serial
// number); the grid is the meter's fixed 380–780 nm every 1 nm (401 values).
//
// Configure sets the speed mode (SPMS: normal, where the meter chooses the integration, for an
// adaptive plan; manual with the plan's integration time otherwise) and the sync mode (SCMS).
// The CS-2000 has no averaging setting: more than one average is refused (kInvalidArgument).
//
// Measure sends MEAS,1: the meter answers at once with the measuring time it will take
// ("OK00,5"), and again when the measurement is done (OK00, or ERxx). The code goes through the
// quality policy as the PR-650 code with the same handling (cs2000::PolicyCodeFor): ER10 (over
// the measurement range) as 19 (a halved manual integration), ER71 (sync) as 07, ER02 as 29.
// TransferSpectrum reads the four spectral blocks (MEDR,1,0,1 … 4): 100 + 100 + 100 + 101 values.
// MeasureSpectrum (the interface's default) lets the stage move while the blocks come.
//
// Errors: kTimeout (silence; the rig then connects again, which sends RMTS,1), kCancelled,
// kDeviceError (device_code = the ERxx number), kProtocolError, kDisconnected (port vanished),
// kConfigurationError, kInvalidArgument, kFailedPrecondition (not connected, nothing measured).
#pragma once

#include <optional>
#include <string>

#include "drivers/cs2000/options.h"
#include "drivers/cs2000/protocol.h"
#include "drivers/line_meter/connection.h"
#include "drivers/pr650/quality_loop.h"
#include "drivers/spectroradiometer.h"

namespace brdf::drivers {

class Cs2000Spectroradiometer final : public Spectroradiometer {
 public:
  explicit Cs2000Spectroradiometer(
      Cs2000Options options,
      serial::CommandChannel::LinkFactory link_factory = serial::MakeSerialLink);
  ~Cs2000Spectroradiometer() override;

  Status Connect(const CallContext& ctx) override;
  void Disconnect() override;
  bool connected() const override { return connection_.connected(); }

  Result<MeterIdentity> Identify(const CallContext& ctx) override;
  Status Configure(const MeasurementSettings& settings, const CallContext& ctx) override;
  Result<MeasurementOutcome> Measure(const CallContext& ctx) override;
  Result<SpectrumReport> TransferSpectrum(const CallContext& ctx) override;

  const Cs2000Options& options() const { return options_; }

 private:
  struct Setup {
    int integration_ms = 0;  // 0: the meter chooses (normal speed mode)
    bool sync = false;
    friend bool operator==(const Setup&, const Setup&) = default;
  };

  // RMTS,1 until the meter answers OK00 (on an open port).
  Status EnterRemoteMode(const CallContext& ctx);
  // Sends `command`, reads its one-line reply and checks it is OK00.
  Result<cs2000::Reply> Ask(std::string_view command, std::chrono::milliseconds timeout,
                            const CallContext& ctx);
  Status Apply(const Setup& setup, const CallContext& ctx);
  // One MEAS,1: the meter's check code for the measurement (OK00, or ERxx).
  Result<cs2000::Reply> MeasureOnce(const CallContext& ctx);
  Status PrepareRemeasure(const pr650::QualityDecision& decision, int code,
                          pr650::QualityLoop& loop, const CallContext& ctx);
  Status Lost(const Status& status);

  Cs2000Options options_;
  LineMeterConnection connection_;
  std::optional<Setup> configured_;
  std::optional<Setup> meter_setup_;
  bool dark_ = false;
  bool holds_measurement_ = false;
};

}  // namespace brdf::drivers
