#include "drivers/pr670/spectroradiometer.h"

#include "drivers/pr650/protocol.h"
#include "drivers/serial/context_wait.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers {

Pr670Spectroradiometer::Pr670Spectroradiometer(Pr670Options options,
                                               serial::CommandChannel::LinkFactory link_factory)
    : options_(WithStderrLog(std::move(options), "pr670")),
      connection_(options_, "\r", options_.char_gap, std::move(link_factory)) {
  // A PR-655 reports 101 bands, 4 nm apart; D120 tells either once identified.
  if (options_.model == "PR-655") grid_ = WavelengthGrid::Pr650();
}

Pr670Spectroradiometer::~Pr670Spectroradiometer() {
  Disconnect();
}

Status Pr670Spectroradiometer::Lost(const Status& status) {
  if (connection_.NoteIfLost()) {
    held_.reset();
    meter_setup_.reset();
  }
  return status;
}

// ---- Connect -----------------------------------------------------------------------------------

Status Pr670Spectroradiometer::EnterRemoteMode(const CallContext& ctx) {
  Status last;
  for (int attempt = 1; attempt <= options_.remote_attempts; ++attempt) {
    // Q first: a meter left in remote mode answers the next PHOTO only after leaving it.
    BRDF_RETURN_IF_ERROR(connection_.channel().Send(pr670::kQuitCommand, ctx));
    BRDF_RETURN_IF_ERROR(serial::WaitChecked(options_.quit_settle, ctx,
                                             "letting the meter leave "
                                             "remote mode"));
    BRDF_RETURN_IF_ERROR(connection_.channel().Send(pr670::kRemoteModeCommand, ctx));
    Result<std::string> answer = connection_.channel().ReadMore(
        pr670::kRemoteModeCommand, {.lines = 1, .first_byte_timeout = options_.remote_timeout},
        ctx);
    if (answer.ok()) {
      connection_.Log(connection_.Where() + " is in remote mode: \"" + serial::Printable(*answer) +
                      "\"");
      return Status::Ok();
    }
    last = answer.status();
    if (last.code() != StatusCode::kTimeout || ctx.expired()) return last;
    connection_.Log("remote-mode attempt " + std::to_string(attempt) + " of " +
                    std::to_string(options_.remote_attempts) + " on " + options_.port + ": " +
                    last.ToString());
  }
  return Timeout(connection_.Where() + " did not answer PHOTO in " +
                 std::to_string(options_.remote_attempts) + " attempt(s) of " +
                 std::to_string(options_.remote_timeout.count()) +
                 " ms: the meter is not entering remote mode. Check that it is switched on and "
                 "its USB cable is in, that no other program has the port, and that its screen "
                 "is not in a menu; then connect again");
}

Status Pr670Spectroradiometer::Connect(const CallContext& ctx) {
  if (connection_.connected()) return Status::Ok();
  BRDF_RETURN_IF_ERROR(ValidatePr670Options(options_));
  BRDF_RETURN_IF_ERROR(connection_.Connect([&] { return EnterRemoteMode(ctx); }));
  meter_setup_.reset();  // a meter re-entering remote mode may not keep ours
  held_.reset();
  return Status::Ok();
}

void Pr670Spectroradiometer::Disconnect() {
  connection_.Disconnect([this] {
    // Leave remote mode, so the meter's own buttons work again; best effort.
    const CallContext ctx = CallContext::WithTimeout(std::chrono::seconds(1));
    (void)connection_.channel().Send(pr670::kQuitCommand, ctx);
  });
  held_.reset();
  meter_setup_.reset();
}

// ---- Exchanges ---------------------------------------------------------------------------------

Result<std::string> Pr670Spectroradiometer::Ask(std::string_view command,
                                                std::chrono::milliseconds timeout,
                                                const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  Result<std::string> reply =
      connection_.channel().Exchange(command, {.lines = 1, .first_byte_timeout = timeout}, ctx);
  if (!reply.ok()) return Lost(reply.status());
  return reply;
}

Status Pr670Spectroradiometer::SetOne(const std::string& command, const CallContext& ctx) {
  BRDF_ASSIGN_OR_RETURN(const std::string reply, Ask(command, options_.reply_timeout, ctx));
  BRDF_ASSIGN_OR_RETURN(const int code, pr670::ParseResultCode(reply, command));
  if (code != 0) {
    return DeviceError(code, connection_.Where() + " refused " + command + ": result code " +
                                 pr670::DescribeResultCode(code) +
                                 "; check the measurement settings against the meter's range");
  }
  return Status::Ok();
}

Status Pr670Spectroradiometer::Apply(const Setup& setup, const CallContext& ctx) {
  meter_setup_.reset();  // unknown until every command is accepted
  BRDF_ASSIGN_OR_RETURN(const std::string exposure, pr670::ExposureCommand(setup.exposure_ms));
  BRDF_ASSIGN_OR_RETURN(const std::string averages, pr670::AveragesCommand(setup.averages));
  BRDF_RETURN_IF_ERROR(SetOne(exposure, ctx));
  BRDF_RETURN_IF_ERROR(SetOne(averages, ctx));
  BRDF_RETURN_IF_ERROR(SetOne(pr670::SyncCommand(setup.sync), ctx));
  meter_setup_ = setup;
  return Status::Ok();
}

// ---- Spectroradiometer -------------------------------------------------------------------------

Result<MeterIdentity> Pr670Spectroradiometer::Identify(const CallContext& ctx) {
  BRDF_ASSIGN_OR_RETURN(const std::string name_reply,
                        Ask(pr670::kModelCommand, options_.reply_timeout, ctx));
  BRDF_ASSIGN_OR_RETURN(const std::string name,
                        pr670::ParseTextReply(name_reply, pr670::kModelCommand));
  BRDF_ASSIGN_OR_RETURN(const std::string serial_reply,
                        Ask(pr670::kSerialNumberCommand, options_.reply_timeout, ctx));
  BRDF_ASSIGN_OR_RETURN(const std::string serial,
                        pr670::ParseTextReply(serial_reply, pr670::kSerialNumberCommand));
  BRDF_ASSIGN_OR_RETURN(const std::string layout_reply,
                        Ask(pr670::kLayoutCommand, options_.reply_timeout, ctx));
  BRDF_ASSIGN_OR_RETURN(grid_, pr670::ParseLayoutReply(layout_reply));
  connection_.set_model(name);
  return MeterIdentity{name, serial, grid_};
}

Status Pr670Spectroradiometer::Configure(const MeasurementSettings& settings,
                                         const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  const Setup setup{settings.integration_ms, settings.averages, settings.sync_to_source};
  BRDF_RETURN_IF_ERROR(pr670::ExposureCommand(setup.exposure_ms).status());
  BRDF_RETURN_IF_ERROR(pr670::AveragesCommand(setup.averages).status());
  configured_.reset();
  BRDF_RETURN_IF_ERROR(Apply(setup, ctx));
  configured_ = setup;
  dark_ = settings.dark;
  return Status::Ok();
}

Result<std::string> Pr670Spectroradiometer::MeasureOnce(
    const CallContext& ctx, const std::function<void(std::string_view)>& on_header) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  const Setup current = meter_setup_.value_or(Setup{});
  const std::chrono::milliseconds timeout =
      Pr670MeasurementTimeout(options_, current.exposure_ms, current.averages);
  const std::size_t full = pr670::SpectrumReplyLines(grid_);
  serial::ReplyShape shape;
  shape.lines = full;
  shape.first_byte_timeout = timeout;
  shape.first_line = on_header;
  // A failed measurement is answered with its code alone.
  shape.lines_after_first = [full](std::string_view line) -> std::size_t {
    Result<int> code = pr670::ParseResultCode(line, pr670::kMeasureSpectrumCommand);
    return code.ok() && *code != 0 ? 1 : full;
  };
  Result<std::string> reply =
      connection_.channel().Exchange(pr670::kMeasureSpectrumCommand, shape, ctx);
  if (!reply.ok()) {
    Status st = reply.status();
    if (st.code() == StatusCode::kTimeout && !ctx.expired()) {
      st = Timeout(st.message() + ": the measurement did not end within " +
                   std::to_string(timeout.count()) + " ms (averages × exposure plus a margin of " +
                   std::to_string(options_.measurement_timeout.count()) +
                   " ms, [meter] measurement_timeout_ms); if the meter left remote mode or was "
                   "switched off, it is connected again");
    }
    return Lost(st);
  }
  return reply;
}

Status Pr670Spectroradiometer::PrepareRemeasure(const pr650::QualityDecision& decision, int code,
                                                pr650::QualityLoop& loop, const CallContext& ctx) {
  if (decision.kind == pr650::QualityDecision::Kind::kFail) {
    return loop.Failure(code, code == -8 ? "more light, or a longer fixed exposure"
                                         : "see the result codes in the meter's manual");
  }
  Setup changed = meter_setup_.value_or(configured_.value_or(Setup{}));
  changed.exposure_ms = decision.new_integration_ms;
  changed.sync = decision.new_sync;
  if (meter_setup_ == changed) return Status::Ok();
  return Apply(changed, ctx);
}

Result<SpectrumReport> Pr670Spectroradiometer::ReportFrom(const std::string& reply, int code,
                                                          pr650::QualityLoop& loop) const {
  SpectrumReport report;
  report.quality_code = code;
  if (code != 0) {
    // Accepted without data (too dark on a dark reading): the meter measured less than it can
    // see; the open drivers record zeros (Psychtoolbox's PR670measspd).
    report.grid = grid_;
    report.radiance.assign(grid_.count, 0.0);
    loop.Note("the meter sends no spectrum with code " + std::to_string(code) +
              ": recorded as zeros");
    return report;
  }
  BRDF_ASSIGN_OR_RETURN(pr670::SpectrumReply parsed,
                        pr670::ParseSpectrumReply(reply, grid_, pr670::kMeasureSpectrumCommand));
  report.grid = parsed.grid;
  report.radiance = std::move(parsed.values);
  report.units_code = parsed.header.units_code;
  report.integrated = parsed.header.integrated;
  if (report.units_code != 0) {
    loop.Note("units code " + std::to_string(report.units_code) +
              ": not radiance (the accessory fitted measures another quantity); check it");
  }
  return report;
}

Result<MeasuredSpectrum> Pr670Spectroradiometer::MeasureLoop(const CallContext& ctx,
                                                             const MeasuredCallback& measured) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  held_.reset();
  if (configured_ && meter_setup_ != configured_) BRDF_RETURN_IF_ERROR(Apply(*configured_, ctx));
  pr650::QualityLoop loop(options_.quality_policy, options_.max_measure_attempts, dark_,
                          options_.log, connection_.Where());
  for (;; loop.NextAttempt()) {
    const Setup current = meter_setup_.value_or(Setup{});
    std::optional<int> code;
    pr650::QualityDecision decision;
    auto judge = [&](std::string_view line) {
      Result<int> parsed = pr670::ParseResultCode(line, pr670::kMeasureSpectrumCommand);
      if (!parsed.ok()) return;  // the whole reply's parse says what is wrong
      code = *parsed;
      const pr670::ResultCodeInfo* info = pr670::FindResultCode(*code);
      decision = loop.Judge(*code, info ? info->meaning : "unknown result code",
                            pr670::PolicyCodeFor(*code), current.exposure_ms, current.sync);
      if (pr650::QualityLoop::Accepted(decision) && measured) {
        measured(loop.Outcome(*code, decision, current.exposure_ms));
      }
    };
    BRDF_ASSIGN_OR_RETURN(const std::string reply, MeasureOnce(ctx, judge));
    if (!code) {
      BRDF_RETURN_IF_ERROR(pr670::ParseResultCode(reply, pr670::kMeasureSpectrumCommand).status());
      return ProtocolError(connection_.Where() + ": M5 reply had no result code");  // unreachable
    }
    if (!pr650::QualityLoop::Accepted(decision)) {
      BRDF_RETURN_IF_ERROR(PrepareRemeasure(decision, *code, loop, ctx));
      continue;
    }
    BRDF_ASSIGN_OR_RETURN(SpectrumReport report, ReportFrom(reply, *code, loop));
    MeasurementOutcome outcome = loop.Outcome(*code, decision, current.exposure_ms);
    if (report.units_code != 0) outcome.flagged = true;
    held_ = report;
    return MeasuredSpectrum{std::move(outcome), std::move(report)};
  }
}

Result<MeasurementOutcome> Pr670Spectroradiometer::Measure(const CallContext& ctx) {
  BRDF_ASSIGN_OR_RETURN(MeasuredSpectrum m, MeasureLoop(ctx, nullptr));
  return m.outcome;
}

Result<SpectrumReport> Pr670Spectroradiometer::TransferSpectrum(const CallContext& ctx) {
  (void)ctx;
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  if (!held_) {
    return FailedPrecondition(connection_.Where() +
                              " holds no accepted measurement: call Measure first");
  }
  return *held_;
}

Result<MeasuredSpectrum> Pr670Spectroradiometer::MeasureSpectrum(const CallContext& ctx,
                                                                 const MeasuredCallback& measured) {
  return MeasureLoop(ctx, measured);
}

}  // namespace brdf::drivers
