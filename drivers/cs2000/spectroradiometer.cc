#include "drivers/cs2000/spectroradiometer.h"

#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers {

Cs2000Spectroradiometer::Cs2000Spectroradiometer(Cs2000Options options,
                                                 serial::CommandChannel::LinkFactory link_factory)
    : options_(WithStderrLog(std::move(options), "cs2000")),
      connection_(options_, "\n", std::chrono::milliseconds(0), std::move(link_factory)) {}

Cs2000Spectroradiometer::~Cs2000Spectroradiometer() {
  Disconnect();
}

Status Cs2000Spectroradiometer::Lost(const Status& status) {
  if (connection_.NoteIfLost()) {
    holds_measurement_ = false;
    meter_setup_.reset();
  }
  return status;
}

Status Cs2000Spectroradiometer::EnterRemoteMode(const CallContext& ctx) {
  Status status;
  for (int attempt = 1; attempt <= options_.remote_attempts; ++attempt) {
    Result<std::string> reply = connection_.channel().Exchange(
        cs2000::kRemoteOnCommand, {.lines = 1, .first_byte_timeout = options_.reply_timeout}, ctx);
    if (reply.ok()) {
      status = cs2000::ParseOkReply(*reply, cs2000::kRemoteOnCommand).status();
      break;
    }
    status = reply.status();
    if (status.code() != StatusCode::kTimeout || ctx.expired()) break;
    connection_.Log("RMTS,1 attempt " + std::to_string(attempt) + " on " + options_.port + ": " +
                    status.ToString());
  }
  if (status.code() == StatusCode::kTimeout && !ctx.expired()) {
    status = Timeout(connection_.Where() + " did not answer RMTS,1 in " +
                     std::to_string(options_.remote_attempts) +
                     " attempt(s): check that it is "
                     "switched on, that its cable is in (RS-232C: the baud rate set on the meter "
                     "matches [meter] baud) and that no other program has the port");
  }
  return status;
}

Status Cs2000Spectroradiometer::Connect(const CallContext& ctx) {
  if (connection_.connected()) return Status::Ok();
  BRDF_RETURN_IF_ERROR(ValidateCs2000Options(options_));
  BRDF_RETURN_IF_ERROR(connection_.Connect([&] { return EnterRemoteMode(ctx); }));
  meter_setup_.reset();
  holds_measurement_ = false;
  return Status::Ok();
}

void Cs2000Spectroradiometer::Disconnect() {
  connection_.Disconnect([this] {
    // Remote mode off, so the meter's own keys work again; best effort.
    const CallContext ctx = CallContext::WithTimeout(std::chrono::milliseconds(500));
    (void)connection_.channel().Exchange(
        cs2000::kRemoteOffCommand,
        {.lines = 1, .first_byte_timeout = std::chrono::milliseconds(400)}, ctx);
  });
  holds_measurement_ = false;
  meter_setup_.reset();
}

Result<cs2000::Reply> Cs2000Spectroradiometer::Ask(std::string_view command,
                                                   std::chrono::milliseconds timeout,
                                                   const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  Result<std::string> reply =
      connection_.channel().Exchange(command, {.lines = 1, .first_byte_timeout = timeout}, ctx);
  if (!reply.ok()) return Lost(reply.status());
  return cs2000::ParseOkReply(*reply, command);
}

Status Cs2000Spectroradiometer::Apply(const Setup& setup, const CallContext& ctx) {
  meter_setup_.reset();
  BRDF_ASSIGN_OR_RETURN(const std::string speed,
                        cs2000::SpeedCommand(setup.integration_ms, options_.nd_filter));
  BRDF_ASSIGN_OR_RETURN(const std::string sync,
                        cs2000::SyncCommand(setup.sync, options_.sync_frequency_hz));
  BRDF_RETURN_IF_ERROR(Ask(speed, options_.reply_timeout, ctx).status());
  BRDF_RETURN_IF_ERROR(Ask(sync, options_.reply_timeout, ctx).status());
  meter_setup_ = setup;
  return Status::Ok();
}

Result<MeterIdentity> Cs2000Spectroradiometer::Identify(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  Result<std::string> reply = connection_.channel().Exchange(
      cs2000::kIdentityCommand, {.lines = 1, .first_byte_timeout = options_.reply_timeout}, ctx);
  if (!reply.ok()) return Lost(reply.status());
  BRDF_ASSIGN_OR_RETURN(const cs2000::Identity id, cs2000::ParseIdentityReply(*reply));
  connection_.set_model(id.model);
  return MeterIdentity{id.model, id.serial_number, cs2000::Grid()};
}

Status Cs2000Spectroradiometer::Configure(const MeasurementSettings& settings,
                                          const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  if (settings.averages != 1) {
    return InvalidArgument(connection_.Where() + " cannot average " +
                           std::to_string(settings.averages) +
                           " measurements: the CS-2000 has no averaging setting; plan 1 average "
                           "(a longer integration time lowers the noise instead)");
  }
  const Setup setup{settings.integration_ms, settings.sync_to_source};
  BRDF_RETURN_IF_ERROR(cs2000::SpeedCommand(setup.integration_ms, options_.nd_filter).status());
  configured_.reset();
  BRDF_RETURN_IF_ERROR(Apply(setup, ctx));
  configured_ = setup;
  dark_ = settings.dark;
  return Status::Ok();
}

Result<cs2000::Reply> Cs2000Spectroradiometer::MeasureOnce(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  constexpr std::string_view kCommand = cs2000::kMeasureCommand;
  Result<std::string> start = connection_.channel().Exchange(
      kCommand, {.lines = 1, .first_byte_timeout = options_.measure_start_timeout}, ctx);
  if (!start.ok()) return Lost(start.status());
  // A short measurement's completion may follow its measuring time closely enough to arrive in
  // the same read: the first line is the time, a second one the completion.
  const std::vector<std::string> lines = serial::SplitReplyLines(*start);
  BRDF_ASSIGN_OR_RETURN(const cs2000::Reply first, cs2000::ParseReply(lines.front(), kCommand));
  if (!first.ok) return first;  // refused before measuring (e.g. over range at once)
  BRDF_ASSIGN_OR_RETURN(const int seconds, cs2000::ParseMeasuringTime(lines.front()));
  std::string completion = lines.size() > 1 ? lines[1] : std::string();
  if (lines.size() > 2) {
    return ProtocolError(connection_.Where() + " answered MEAS,1 with " +
                         std::to_string(lines.size()) + " lines (\"" + serial::Printable(*start) +
                         "\"); expected the measuring time, then the completion");
  }
  if (completion.empty()) {
    const auto timeout = std::chrono::milliseconds(seconds * 1000LL) + options_.measurement_timeout;
    Result<std::string> done =
        connection_.channel().ReadMore(kCommand, {.lines = 1, .first_byte_timeout = timeout}, ctx);
    if (!done.ok()) {
      Status st = done.status();
      if (st.code() == StatusCode::kTimeout && !ctx.expired()) {
        st = Timeout(
            connection_.Where() + " announced a measuring time of " + std::to_string(seconds) +
            " s but did not report the measurement done within " + std::to_string(timeout.count()) +
            " ms ([meter] measurement_timeout_ms is "
            "the margin); if it left remote mode or was switched off, it is connected "
            "again");
      }
      return Lost(st);
    }
    completion = *done;
  }
  return cs2000::ParseReply(completion, kCommand);
}

Status Cs2000Spectroradiometer::PrepareRemeasure(const pr650::QualityDecision& decision, int code,
                                                 pr650::QualityLoop& loop, const CallContext& ctx) {
  if (decision.kind == pr650::QualityDecision::Kind::kFail) {
    return loop.Failure(code, code == 10 ? "less light, or a shorter manual integration time"
                                         : "see the error codes in the meter's manual");
  }
  Setup changed = meter_setup_.value_or(configured_.value_or(Setup{}));
  changed.integration_ms = decision.new_integration_ms;
  changed.sync = decision.new_sync;
  if (meter_setup_ == changed) return Status::Ok();
  return Apply(changed, ctx);
}

Result<MeasurementOutcome> Cs2000Spectroradiometer::Measure(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  holds_measurement_ = false;
  if (configured_ && meter_setup_ != configured_) BRDF_RETURN_IF_ERROR(Apply(*configured_, ctx));
  pr650::QualityLoop loop(options_.quality_policy, options_.max_measure_attempts, dark_,
                          options_.log, connection_.Where());
  for (;; loop.NextAttempt()) {
    const Setup current = meter_setup_.value_or(Setup{});
    BRDF_ASSIGN_OR_RETURN(const cs2000::Reply check, MeasureOnce(ctx));
    // OK00 is code 0; ERxx is xx (ER00, a refused command, fails whatever the policy says).
    const int code = check.ok ? 0 : check.code;
    const std::string meaning = check.ok ? "OK00" : cs2000::DescribeErrorCode(code);
    const pr650::QualityDecision decision =
        loop.Judge(code, meaning, check.ok ? 0 : cs2000::PolicyCodeFor(code),
                   current.integration_ms, current.sync);
    if (pr650::QualityLoop::Accepted(decision)) {
      holds_measurement_ = check.ok;
      if (!holds_measurement_) {
        return loop.Failure(code, "the meter holds no data after " +
                                      cs2000::DescribeErrorCode(code) +
                                      "; a [meter.quality] rule that accepts it cannot help");
      }
      return loop.Outcome(code, decision, current.integration_ms);
    }
    BRDF_RETURN_IF_ERROR(PrepareRemeasure(decision, code, loop, ctx));
  }
}

Result<SpectrumReport> Cs2000Spectroradiometer::TransferSpectrum(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(connection_.RequireConnected());
  if (!holds_measurement_) {
    return FailedPrecondition(connection_.Where() +
                              " holds no accepted measurement: call Measure first");
  }
  SpectrumReport report;
  report.grid = cs2000::Grid();
  report.radiance.reserve(report.grid.count);
  for (int block = 1; block <= cs2000::kBlocks; ++block) {
    const std::string command = cs2000::SpectralBlockCommand(block);
    Result<std::string> reply = connection_.channel().Exchange(
        command, {.lines = 1, .first_byte_timeout = options_.reply_timeout}, ctx);
    if (!reply.ok()) return Lost(reply.status());
    BRDF_ASSIGN_OR_RETURN(const std::vector<double> values,
                          cs2000::ParseSpectralBlock(*reply, block));
    report.radiance.insert(report.radiance.end(), values.begin(), values.end());
  }
  double integrated = 0;
  for (double v : report.radiance) integrated += v * report.grid.step_nm;
  report.integrated = integrated;
  return report;
}

}  // namespace brdf::drivers
