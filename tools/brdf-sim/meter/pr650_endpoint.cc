#include "tools/brdf-sim/meter/pr650_endpoint.h"

#include <algorithm>
#include <cstdio>

#include "tools/brdf-sim/meter/pr650_protocol.h"

namespace brdf::sim {

namespace {

// The reports brdf-sim answers: D1 (Y, x, y), D2 (X, Y, Z), D3 (Y, u', v'), D4 (Y, colour
// temperature, its deviation), D5 (spectrum), D6 (Y, x, y, u', v').
bool IsServedReport(int report) {
  return report >= 1 && report <= 6;
}

// The response code of an M or D command, by value: "M5", "M05" and "M005" are all 5. A bare "M"
// is M1 (the meter's default response code); a bare "D" or anything not digits is no code.
std::optional<int> ResponseCode(const std::string& command) {
  if (command.empty() || (command[0] != 'M' && command[0] != 'D')) return std::nullopt;
  if (command.size() == 1) return command[0] == 'M' ? std::optional<int>(1) : std::nullopt;
  if (command.size() > 5) return std::nullopt;
  int code = 0;
  for (std::size_t i = 1; i < command.size(); ++i) {
    if (command[i] < '0' || command[i] > '9') return std::nullopt;
    code = code * 10 + (command[i] - '0');
  }
  return code;
}

LineEndpointOptions LineOptionsOf(const Pr650EndpointOptions& o) {
  const Pr650WireQuirks& q = o.quirks;
  LineEndpointOptions line;
  line.time_scale = o.time_scale;
  line.pace_replies = o.pace_replies;
  line.baud = o.baud;
  line.fifo_bytes = o.fifo_bytes;
  line.link_path = o.link_path;
  line.serial_number = o.serial_number;
  line.eol = q.line_ending == Pr650WireQuirks::LineEnding::kLf   ? "\n"
             : q.line_ending == Pr650WireQuirks::LineEnding::kCr ? "\r"
                                                                 : "\r\n";
  line.piece_bytes = q.piece_bytes;
  line.piece_gap = q.piece_gap;
  line.reply_delay = q.reply_delay;
  line.delayed_replies = q.delayed_replies;
  return line;
}

}  // namespace

Pr650Endpoint::Pr650Endpoint(MeterBackend& backend, SimControl& control,
                             Pr650EndpointOptions options)
    : LineMeterEndpoint(backend, control, LineOptionsOf(options)), pr650_(std::move(options)) {}

Pr650Endpoint::~Pr650Endpoint() {
  Stop();
}

void Pr650Endpoint::OnPowerOn() {
  power_on_ = SteadyClock::now().time_since_epoch().count();
  forget_ = true;
}

void Pr650Endpoint::OnCharacter(char c) {
  ForgetIfSwitchedOff();
  LineMeterEndpoint::OnCharacter(c);
}

void Pr650Endpoint::ForgetIfSwitchedOff() {
  if (!forget_.exchange(false)) return;
  input_.clear();  // what was typed before the meter went off is lost
  standalone_ = false;
  setup_ = MeterSetup{};
  sync_ = false;
  last_setup_reply_ = 0;
  last_ = Measurement{};
}

std::string Pr650Endpoint::LineEnd(std::size_t line, std::size_t count) const {
  const bool bare_cr = pr650_.quirks.d5_header_bare_cr && line == 0 && count > 2;
  return bare_cr ? "\r" : LineMeterEndpoint::LineEnd(line, count);
}

void Pr650Endpoint::Handle(const std::string& command) {
  if (!AdmitCommand(command)) return;
  if (command.size() == 2 && command[0] == 'B' && command[1] >= '0' && command[1] <= '3') {
    Reply({"000"});
    return;
  }
  if (command[0] == 'S') {
    HandleSetup(command);
    return;
  }
  if (command == "F") {
    char text[32];
    std::snprintf(text, sizeof text, "00,%.1f", pr650_.flicker_hz);
    Reply({text + pr650_.flicker_reply_suffix});
    return;
  }
  const std::optional<int> code = ResponseCode(command);
  if (!code.has_value()) return;  // unknown: the simulated meter does not answer
  if (command[0] == 'M' && (*code == 0 || IsServedReport(*code))) {
    HandleMeasure(*code);
    return;
  }
  if (command[0] != 'D') return;  // M7 … M98: not served
  HandleReport(*code);
}

bool Pr650Endpoint::AdmitCommand(const std::string& command) {
  const SteadyClock::time_point on{SteadyClock::duration(power_on_.load())};
  const double since_power_on = options().time_scale.ToSim(
      std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now() - on));
  const bool wakes =
      !standalone_ && (pr650_.wake_window_s <= 0 || since_power_on <= pr650_.wake_window_s);
  if (!Admit(command, wakes)) {
    // The first command too late: stand-alone until power-cycled.
    if (!wakes && !remote_mode()) standalone_ = true;
    return false;
  }
  if (!remote_mode()) SetRemote(true);
  return true;
}

void Pr650Endpoint::HandleSetup(const std::string& command) {
  const Pr650SetupResult result = ApplyPr650Setup(std::string_view(command).substr(1));
  last_setup_reply_ = result.reply_code;
  if (result.reply_code == 0) {
    setup_ = result.setup;
    sync_ = result.sync;
  }
  char text[8];
  std::snprintf(text, sizeof text, "%02d", result.reply_code);
  Reply({text});
}

void Pr650Endpoint::HandleMeasure(int code) {
  // M0 measures and holds; Mn is M0 followed by report n, in one reply.
  const std::optional<int> quality_code = Measure();
  if (!quality_code.has_value()) return;
  if (code != 0) {
    ReplyReport(code);
    return;
  }
  const int status = pr650_.m0_reply_is_quality ? std::clamp(*quality_code, 0, 999) : 0;
  char text[8];
  std::snprintf(text, sizeof text, "%03d", status);
  Reply({text});
}

void Pr650Endpoint::HandleReport(int code) {
  if (IsServedReport(code)) {
    ReplyReport(code);
    return;
  }
  if (code == 110) {
    std::string serial = pr650_.serial_number.substr(0, 8);
    serial.resize(8, ' ');
    Reply({serial});
    return;
  }
  if (code == 120) {
    Reply({Pr650LayoutLine()});
    return;
  }
  if (code == 201) {
    // The reply to the last S command again ("pp"); 00 before any.
    char text[8];
    std::snprintf(text, sizeof text, "%02d", last_setup_reply_);
    Reply({text});
    return;
  }
  // Other response codes (D19's binary block, D111, ...): no source documents them for the
  // PR-650; the simulated meter does not answer.
}

std::optional<int> Pr650Endpoint::Measure() {
  std::optional<Taken> taken = TakeMeasurement(setup_);
  if (!taken.has_value()) return std::nullopt;
  SimMeasurement& m = taken->measurement;
  if (taken->forced_code.has_value()) m.quality_code = *taken->forced_code;
  // A measurement that gave no data leaves nothing to report: the reports answer "-1".
  last_ = taken->no_data ? Measurement{}
                         : Measurement{true, m.quality_code, m.integrated, std::move(m.radiance)};
  return m.quality_code;
}

void Pr650Endpoint::ReplyReport(int report) {
  if (!last_.valid) {
    Reply({kNoMeasurementReply});
    return;
  }
  const int units_code = control_.serial().units_code;
  if (report != 5) {
    Reply({Pr650ColorimetryLine(report, last_.quality_code, units_code,
                                Pr650TristimulusOf(last_.radiance))});
    return;
  }
  Reply(Pr650SpectrumLines(last_.quality_code, units_code, last_.integrated, last_.radiance),
        TakeVanish());
}

}  // namespace brdf::sim
