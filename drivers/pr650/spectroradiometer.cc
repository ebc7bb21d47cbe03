#include "drivers/pr650/spectroradiometer.h"

#include <iostream>

#include "drivers/pr650/quality_codes.h"
#include "drivers/serial/context_wait.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers {

namespace {

using pr650::SetupFields;

constexpr std::string_view kModel = "PR-650";

long long Millis(std::chrono::steady_clock::duration d) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
}

std::string JoinNotes(const std::vector<std::string>& notes) {
  std::string out;
  for (const std::string& n : notes) {
    if (n.empty()) continue;
    if (!out.empty()) out += "; ";
    out += n;
  }
  return out;
}

}  // namespace

Pr650Spectroradiometer::Pr650Spectroradiometer(Pr650Options options, LinkFactory link_factory)
    : options_(std::move(options)), link_factory_(std::move(link_factory)) {
  if (!options_.log) {
    options_.log = [](std::string_view message) { std::clog << "pr650: " << message << '\n'; };
  }
  framing_.quiet_gap = options_.quiet_gap;
  framing_.stall_timeout = options_.stall_timeout;
}

Pr650Spectroradiometer::~Pr650Spectroradiometer() {
  DropLink();
}

void Pr650Spectroradiometer::Log(const std::string& message) const {
  options_.log(message);
}

void Pr650Spectroradiometer::DropLink() {
  if (link_) link_->Close();
  link_.reset();
  connected_ = false;
  holds_measurement_ = false;
  meter_setup_.reset();
  late_reply_until_.reset();
}

void Pr650Spectroradiometer::Disconnect() {
  DropLink();
  lost_connection_ = false;
}

Status Pr650Spectroradiometer::RequireConnected() const {
  if (connected_) return Status::Ok();
  if (lost_connection_) {
    return Disconnected("PR-650 on " + options_.port +
                        " lost its connection earlier: connect again once the port is back");
  }
  return FailedPrecondition("PR-650 on " + options_.port + " is not connected: call Connect first");
}

Status Pr650Spectroradiometer::WithSilenceHint(const Status& status, const CallContext& ctx) const {
  // Only silence within the meter's own reply time suggests a meter problem; a caller's deadline
  // that passed first does not.
  if (status.code() != StatusCode::kTimeout || ctx.expired()) return status;
  return Status(StatusCode::kTimeout,
                status.message() +
                    "; the meter may have been switched off or have left remote mode: check "
                    "its power and cable, then connect again (power-cycle it first if it stays "
                    "silent)");
}

// ---- Connect -----------------------------------------------------------------------------------

Status Pr650Spectroradiometer::OpenWithRtsDrop(const CallContext& ctx) {
  const serial::SerialSettings settings{options_.port, options_.baud,
                                        options_.hardware_flow_control};
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<serial::SerialLink> link,
                        link_factory_(settings, options_.log));
  BRDF_RETURN_IF_ERROR(link->Open(port_seen_));
  port_seen_ = true;
  // The meter only enters remote mode on a first command shortly after power-on; the drivers that
  // work drop RTS for more than 50 ms (closing the port) before talking to it.
  BRDF_RETURN_IF_ERROR(link->SetRts(false));
  BRDF_RETURN_IF_ERROR(
      serial::WaitChecked(options_.rts_drop, ctx, "dropping RTS on " + options_.port));
  link->Close();
  BRDF_RETURN_IF_ERROR(link->Open(true));
  BRDF_RETURN_IF_ERROR(link->SetRts(true));
  link_ = std::move(link);
  return serial::WaitChecked(options_.wake_settle, ctx, "letting the PR-650 settle after RTS");
}

Status Pr650Spectroradiometer::Wake(const CallContext& ctx) {
  const std::string command = *pr650::BacklightCommand(options_.wake_backlight);
  Status last;
  for (int attempt = 1; attempt <= options_.wake_attempts; ++attempt) {
    Result<std::string> reply = Exchange(command, 1, options_.reply_timeout, ctx);
    if (reply.ok()) {
      Result<int> code = pr650::ParseStatusReply(*reply, command);
      if (code.ok() && *code == 0) return Status::Ok();
      last = code.ok() ? ProtocolError("PR-650 on " + options_.port + " answered " + command +
                                       " with status " + std::to_string(*code) + " instead of 000")
                       : code.status();
    } else {
      last = reply.status();
      // Silence and noise are what a meter outside remote mode gives; anything else (cancel,
      // deadline, vanished port) ends the attempts.
      const bool retryable = last.code() == StatusCode::kProtocolError ||
                             (last.code() == StatusCode::kTimeout && !ctx.expired());
      if (!retryable) return last;
    }
    Log("wake-up attempt " + std::to_string(attempt) + " of " +
        std::to_string(options_.wake_attempts) + " on " + options_.port +
        " failed: " + last.ToString());
  }
  if (last.code() == StatusCode::kTimeout) {
    return Timeout("PR-650 on " + options_.port + " did not answer " + command + " in " +
                   std::to_string(options_.wake_attempts) + " attempts (" +
                   std::to_string(Millis(options_.reply_timeout)) +
                   " ms each): the meter is not in remote mode. Power-cycle the meter and connect "
                   "within 5 s of switching it on; check that the cable's XFER/CTRLR switch is on "
                   "CTRLR and that the cable is in the meter's RS-232 port");
  }
  return last.WithContext("PR-650 on " + options_.port + " did not wake up after " +
                          std::to_string(options_.wake_attempts) + " attempts");
}

Status Pr650Spectroradiometer::Connect(const CallContext& ctx) {
  if (connected_) return Status::Ok();
  BRDF_RETURN_IF_ERROR(ValidatePr650Options(options_));
  DropLink();
  Status status = OpenWithRtsDrop(ctx);
  if (status.ok()) status = Wake(ctx);
  if (!status.ok()) {
    DropLink();
    return status;
  }
  connected_ = true;
  lost_connection_ = false;
  // The meter keeps its own setup across a reconnect, but not necessarily ours.
  meter_setup_.reset();
  return Status::Ok();
}

// ---- Exchanges ---------------------------------------------------------------------------------

Status Pr650Spectroradiometer::DiscardLateReply(const CallContext& ctx) {
  if (!late_reply_until_) return Status::Ok();
  const auto until = *late_reply_until_;
  const auto now = ctx.clock().Now();
  if (now >= until) {
    late_reply_until_.reset();
    return Status::Ok();
  }
  // A reply to an abandoned command may still be on its way (the meter finishes what it started);
  // wait for it so it is not read as the answer to the next command.
  Result<std::string> late =
      serial::ReadReply(*link_, {"an abandoned command", 1, until - now}, framing_, ctx);
  if (late.ok()) {
    Log("discarded a late reply on " + options_.port + ": \"" + serial::Printable(*late) + "\"");
  } else if (late.status().code() == StatusCode::kCancelled ||
             late.status().code() == StatusCode::kDisconnected || ctx.expired()) {
    return late.status();
  }
  late_reply_until_.reset();
  return Status::Ok();
}

Result<std::string> Pr650Spectroradiometer::Exchange(std::string_view command, std::size_t lines,
                                                     Duration timeout, const CallContext& ctx,
                                                     const FirstLine& first_line) {
  if (!link_) return RequireConnected();
  Status status = DiscardLateReply(ctx);
  if (status.ok()) {
    const auto now = ctx.clock().Now();
    if (now < next_command_at_) {
      status = serial::WaitChecked(next_command_at_ - now, ctx, "pacing PR-650 commands");
    }
  }
  if (status.ok()) status = link_->FlushInput();
  bool sent = false;
  if (status.ok()) {
    status = link_->Write(std::string(command) + "\n", ctx);
    sent = status.ok();
  }
  const auto sent_at = ctx.clock().Now();
  Result<std::string> reply =
      status.ok() ? serial::ReadReply(*link_, {command, lines, timeout, first_line}, framing_, ctx)
                  : Result<std::string>(status);
  next_command_at_ = ctx.clock().Now() + options_.command_pacing;
  if (reply.ok()) return reply;

  switch (reply.status().code()) {
    case StatusCode::kDisconnected:
      DropLink();
      lost_connection_ = true;
      break;
    case StatusCode::kCancelled:
    case StatusCode::kTimeout:
      // A command the meter received may still be answered: remember until when.
      if (const auto until = serial::LateReplyDeadline(
              sent_at, timeout, ctx.clock().Now(), reply.status().code() == StatusCode::kTimeout);
          sent && until) {
        late_reply_until_ = std::max(late_reply_until_.value_or(*until), *until);
      }
      break;
    default:
      break;
  }
  // The reader's messages name the command already; the link's do not.
  if (reply.status().code() == StatusCode::kDisconnected ||
      reply.status().code() == StatusCode::kCancelled) {
    return reply.status().WithContext("PR-650 " + std::string(command));
  }
  return reply.status();
}

pr650::SetupFields Pr650Spectroradiometer::CurrentSetup() const {
  if (meter_setup_) return *meter_setup_;
  if (configured_) return *configured_;
  SetupFields fields;
  fields.accessory = options_.accessory;
  return fields;
}

Status Pr650Spectroradiometer::SendSetup(const SetupFields& fields, const CallContext& ctx) {
  BRDF_ASSIGN_OR_RETURN(std::string command, pr650::FormatSetupCommand(fields));
  meter_setup_.reset();  // unknown until the meter accepts
  Result<std::string> reply = Exchange(command, 1, options_.measurement_timeout, ctx);
  if (!reply.ok()) return WithSilenceHint(reply.status(), ctx);
  BRDF_ASSIGN_OR_RETURN(int code, pr650::ParseSetupReply(*reply));
  if (code != 0) {
    return DeviceError(code, "PR-650 on " + options_.port + " rejected the setup " + command +
                                 ": " + pr650::DescribeSetupReply(code) +
                                 "; check the measurement settings (and the lens accessory)");
  }
  meter_setup_ = fields;
  return Status::Ok();
}

// ---- Spectroradiometer -------------------------------------------------------------------------

Result<MeterIdentity> Pr650Spectroradiometer::Identify(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected());
  Result<std::string> serial_reply =
      Exchange(pr650::kSerialNumberCommand, 1, options_.reply_timeout, ctx);
  if (!serial_reply.ok()) return WithSilenceHint(serial_reply.status(), ctx);
  BRDF_ASSIGN_OR_RETURN(std::string serial, pr650::ParseSerialNumberReply(*serial_reply));

  Result<std::string> layout_reply =
      Exchange(pr650::kLayoutCommand, 1, options_.reply_timeout, ctx);
  if (!layout_reply.ok()) return WithSilenceHint(layout_reply.status(), ctx);
  BRDF_ASSIGN_OR_RETURN(pr650::SpectralLayout layout, pr650::ParseLayoutReply(*layout_reply));
  grid_ = layout.grid();
  return MeterIdentity{std::string(kModel), serial, grid_};
}

Status Pr650Spectroradiometer::Configure(const MeasurementSettings& settings,
                                         const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected());
  SetupFields fields;
  fields.accessory = options_.accessory;
  fields.integration_ms = settings.integration_ms;
  fields.averages = settings.averages;
  fields.sync = settings.sync_to_source;
  fields.si_units = true;
  if (Result<std::string> check = pr650::FormatSetupCommand(fields); !check.ok()) {
    return check.status();
  }
  if (fields.sync) {
    // Sync mode uses the lamp frequency the meter measured last (F).
    Result<std::string> reply =
        Exchange(pr650::kFlickerCommand, 1, options_.measurement_timeout, ctx);
    if (!reply.ok()) return WithSilenceHint(reply.status(), ctx);
    BRDF_ASSIGN_OR_RETURN(pr650::FlickerReply flicker, pr650::ParseFlickerReply(*reply));
    if (flicker.quality_code != 0) {
      return DeviceError(flicker.quality_code,
                         "PR-650 on " + options_.port + " could not measure the lamp's flicker: " +
                             pr650::DescribeQualityCode(flicker.quality_code) +
                             "; check the lamp, or configure without sync to source");
    }
    Log("lamp flicker measured at " + std::to_string(flicker.frequency_hz) + " Hz");
  }
  configured_.reset();
  BRDF_RETURN_IF_ERROR(SendSetup(fields, ctx));
  configured_ = fields;
  dark_ = settings.dark;
  return Status::Ok();
}

pr650::QualityDecision Pr650Spectroradiometer::Judge(int code, int attempt,
                                                     std::vector<std::string>& notes) const {
  const SetupFields current = CurrentSetup();
  const pr650::MeasureLoopState state{current.integration_ms, current.sync, attempt,
                                      options_.max_measure_attempts, dark_};
  pr650::QualityDecision decision = pr650::DecideQuality(options_.quality_policy, code, state);
  if (!decision.note.empty()) {
    notes.push_back(decision.note);
    Log("measurement " + std::to_string(attempt) + " on " + options_.port + ": " + decision.note);
  }
  return decision;
}

bool Pr650Spectroradiometer::Accepted(const pr650::QualityDecision& decision) {
  using Kind = pr650::QualityDecision::Kind;
  return decision.kind == Kind::kAccept || decision.kind == Kind::kAcceptFlagged;
}

MeasurementOutcome Pr650Spectroradiometer::Outcome(int code, const pr650::QualityDecision& decision,
                                                   int attempt,
                                                   const std::vector<std::string>& notes) const {
  MeasurementOutcome outcome;
  outcome.quality_code = code;
  outcome.flagged = decision.kind == pr650::QualityDecision::Kind::kAcceptFlagged;
  outcome.integration_ms = CurrentSetup().integration_ms;
  outcome.attempts = attempt;
  outcome.note = JoinNotes(notes);
  return outcome;
}

Status Pr650Spectroradiometer::PrepareRemeasure(int code, const pr650::QualityDecision& decision,
                                                int attempt, const std::vector<std::string>& notes,
                                                const CallContext& ctx) {
  if (decision.kind == pr650::QualityDecision::Kind::kFail) {
    const pr650::QualityCodeInfo* info = pr650::FindQualityCode(code);
    std::string hint = info && *info->hint ? info->hint : "see the PR-650 manual";
    return DeviceError(code, "PR-650 on " + options_.port + " measurement failed after " +
                                 std::to_string(attempt) + " attempt(s): " + JoinNotes(notes) +
                                 "; " + hint);
  }
  const SetupFields current = CurrentSetup();
  if (decision.new_integration_ms == current.integration_ms && decision.new_sync == current.sync) {
    return Status::Ok();
  }
  SetupFields changed = current;
  changed.integration_ms = decision.new_integration_ms;
  changed.sync = decision.new_sync;
  return SendSetup(changed, ctx);
}

Status Pr650Spectroradiometer::StartMeasuring(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected());
  holds_measurement_ = false;
  // Each measurement starts from the configured settings: an adaptation made for one pose (a
  // halved integration time) does not carry into the next.
  if (configured_ && meter_setup_ != configured_) return SendSetup(*configured_, ctx);
  return Status::Ok();
}

Result<MeasurementOutcome> Pr650Spectroradiometer::Measure(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(StartMeasuring(ctx));
  std::vector<std::string> notes;
  for (int attempt = 1;; ++attempt) {
    BRDF_ASSIGN_OR_RETURN(int code, MeasureAndHold(ctx));
    const pr650::QualityDecision decision = Judge(code, attempt, notes);
    if (Accepted(decision)) {
      holds_measurement_ = true;
      return Outcome(code, decision, attempt, notes);
    }
    BRDF_RETURN_IF_ERROR(PrepareRemeasure(code, decision, attempt, notes, ctx));
  }
}

Result<int> Pr650Spectroradiometer::MeasureAndHold(const CallContext& ctx) {
  constexpr std::string_view kCommand = pr650::kMeasureCommand;
  Result<std::string> reply = Exchange(kCommand, 1, MeasurementTimeout(), ctx);
  if (!reply.ok()) return WithMeasurementHint(reply.status(), ctx);
  BRDF_ASSIGN_OR_RETURN(int code, pr650::ParseStatusReply(*reply, kCommand));
  if (code == pr650::kNoMeasurementStatus) return NoMeasurement(kCommand);
  return code;
}

std::chrono::milliseconds Pr650Spectroradiometer::MeasurementTimeout() const {
  const SetupFields current = CurrentSetup();
  return MeasurementReplyTimeout(options_, current.integration_ms, current.averages);
}

Status Pr650Spectroradiometer::NoMeasurement(std::string_view command) const {
  return DeviceError(pr650::kNoMeasurementStatus,
                     "PR-650 on " + options_.port + " answered " + std::string(command) +
                         " with -1: it holds no measurement to report (the measurement gave no "
                         "data, or the meter was switched off and on since it measured); measure "
                         "again, and check the meter's display if it persists");
}

Status Pr650Spectroradiometer::WithMeasurementHint(const Status& status,
                                                   const CallContext& ctx) const {
  if (status.code() != StatusCode::kTimeout || ctx.expired()) return status;
  const SetupFields current = CurrentSetup();
  const std::string integration =
      current.integration_ms > 0
          ? std::to_string(current.integration_ms) + " ms"
          : "adaptive (up to " + std::to_string(options_.adaptive_integration_max.count()) + " ms)";
  return Status(StatusCode::kTimeout,
                status.message() + ": the measurement did not end within " +
                    std::to_string(MeasurementTimeout().count()) + " ms (" +
                    std::to_string(current.averages) + " average(s) of " + integration +
                    " integration plus a margin of " +
                    std::to_string(options_.measurement_timeout.count()) +
                    " ms, [meter] measurement_timeout_ms). If the meter's display shows it still "
                    "measuring, raise that margin; if it stays blank, check its power and cable, "
                    "then connect again");
}

Result<SpectrumReport> Pr650Spectroradiometer::TransferSpectrum(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(RequireConnected());
  if (!holds_measurement_) {
    return FailedPrecondition("PR-650 on " + options_.port +
                              " holds no accepted measurement: call Measure first");
  }
  bool no_measurement = false;
  Result<std::string> reply = Exchange(
      pr650::kSpectrumCommand, pr650::SpectrumReplyLines(grid_), options_.reply_timeout, ctx,
      [&](std::string_view line) { no_measurement = pr650::IsNoMeasurementReply(line); });
  if (no_measurement) {
    holds_measurement_ = false;
    return NoMeasurement(pr650::kSpectrumCommand);
  }
  if (!reply.ok()) return WithSilenceHint(reply.status(), ctx);
  return SpectrumFromReply(*reply, pr650::kSpectrumCommand);
}

Result<SpectrumReport> Pr650Spectroradiometer::SpectrumFromReply(std::string_view reply,
                                                                 std::string_view command) const {
  BRDF_ASSIGN_OR_RETURN(pr650::SpectrumReply spectrum,
                        pr650::ParseSpectrumReply(reply, grid_, command));
  SpectrumReport report;
  report.grid = spectrum.grid;
  report.radiance = std::move(spectrum.values);
  report.quality_code = spectrum.quality_code;
  report.units_code = spectrum.units_code;
  report.integrated = spectrum.integrated;
  return report;
}

Result<MeasuredSpectrum> Pr650Spectroradiometer::MeasureSpectrum(const CallContext& ctx,
                                                                 const MeasuredCallback& measured) {
  BRDF_RETURN_IF_ERROR(StartMeasuring(ctx));
  // M5: one exchange, the report follows the measurement. Otherwise M0, then D5.
  const bool one_exchange = options_.measure_with_spectrum;
  const std::string_view command =
      one_exchange ? pr650::kMeasureSpectrumCommand : pr650::kSpectrumCommand;
  std::vector<std::string> notes;
  for (int attempt = 1;; ++attempt) {
    std::optional<int> m0_code;  // M0's status, judged already
    pr650::QualityDecision decision;
    if (!one_exchange) {
      BRDF_ASSIGN_OR_RETURN(int status, MeasureAndHold(ctx));
      decision = Judge(status, attempt, notes);
      if (!Accepted(decision)) {
        BRDF_RETURN_IF_ERROR(PrepareRemeasure(status, decision, attempt, notes, ctx));
        continue;
      }
      m0_code = status;
      holds_measurement_ = true;
    }
    // The report's status line is the measurement's quality code in both modes (a meter may answer
    // M0 with 000 and put low light or overload here): judge it as soon as it arrives, and let the
    // caller go on (move the stage) while the bands stream in.
    std::optional<int> code;
    bool no_measurement = false;
    auto judge_status_line = [&](std::string_view line) {
      if (pr650::IsNoMeasurementReply(line)) {
        no_measurement = true;
        return;
      }
      Result<pr650::SpectrumHeader> header = pr650::ParseSpectrumHeader(line, command);
      if (!header.ok()) return;  // the whole reply's parse below says what is wrong
      code = header->quality_code;
      // The code M0 answered with was judged already; the report's is judged when it says more.
      if (m0_code != code) decision = Judge(*code, attempt, notes);
      if (Accepted(decision) && measured) measured(Outcome(*code, decision, attempt, notes));
    };
    const Duration timeout = one_exchange ? Duration(MeasurementTimeout()) : options_.reply_timeout;
    Result<std::string> reply =
        Exchange(command, pr650::SpectrumReplyLines(grid_), timeout, ctx, judge_status_line);
    if (no_measurement || (reply.ok() && pr650::IsNoMeasurementReply(*reply))) {
      holds_measurement_ = false;
      return NoMeasurement(command);
    }
    const bool rejected = code.has_value() && !Accepted(decision);
    if (!reply.ok()) {
      // After a rejected measurement the meter may send its status line alone: the reader then
      // reports a truncated reply, which is no error here (the policy measures again or fails).
      if (!rejected || reply.status().code() != StatusCode::kProtocolError) {
        return one_exchange ? WithMeasurementHint(reply.status(), ctx)
                            : WithSilenceHint(reply.status(), ctx);
      }
    }
    if (!rejected) {
      BRDF_ASSIGN_OR_RETURN(SpectrumReport report, SpectrumFromReply(*reply, command));
      if (!code.has_value()) {  // cannot happen: a parsed report has a status line
        return ProtocolError("PR-650 reply to " + std::string(command) + " on " + options_.port +
                             " had no status line");
      }
      holds_measurement_ = true;
      MeasurementOutcome outcome = Outcome(*code, decision, attempt, notes);
      FlagUnits(report.units_code, outcome);
      return MeasuredSpectrum{std::move(outcome), std::move(report)};
    }
    holds_measurement_ = false;
    BRDF_RETURN_IF_ERROR(PrepareRemeasure(*code, decision, attempt, notes, ctx));
  }
}

void Pr650Spectroradiometer::FlagUnits(int units_code, MeasurementOutcome& outcome) const {
  if (units_code == 0) return;  // spectral radiance, W·m⁻²·sr⁻¹·nm⁻¹
  const std::string note =
      units_code == 2
          ? "units code 2: the meter reports uncalibrated values, not spectral radiance; check its "
            "calibration before using this reading"
          : "units code " + std::to_string(units_code) +
                (units_code == 1 ? ": the meter reports spectral irradiance (W·m⁻²·nm⁻¹), not "
                                   "radiance; check the accessory fitted to it"
                                 : ": not spectral radiance (the PR-650 knows 0, 1 and 2)");
  outcome.flagged = true;
  outcome.note = outcome.note.empty() ? note : outcome.note + "; " + note;
  Log("reading on " + options_.port + " flagged: " + note);
}

}  // namespace brdf::drivers
