#include "tools/brdf-sim/meter/pr650_endpoint.h"

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>

#include "tools/brdf-sim/meter/pr650_protocol.h"
#include "tools/brdf-sim/meter/serial_wire.h"

namespace brdf::sim {

namespace {

constexpr auto kSlice = std::chrono::milliseconds(20);

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

}  // namespace

Pr650Endpoint::Pr650Endpoint(MeterBackend& backend, SimControl& control,
                             Pr650EndpointOptions options)
    : backend_(backend), control_(control), options_(std::move(options)) {}

Pr650Endpoint::~Pr650Endpoint() {
  Stop();
}

Status Pr650Endpoint::Start() {
  Stop();
  {
    std::lock_guard lock(mu_);
    BRDF_RETURN_IF_ERROR(port_.Open(options_.link_path));
    power_on_ = SteadyClock::now();
    remote_ = false;
    standalone_ = false;
    input_.clear();
  }
  stop_ = false;
  thread_ = std::thread([this] { Run(); });
  return Status::Ok();
}

void Pr650Endpoint::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mu_);
  port_.Close();
}

std::string Pr650Endpoint::path() const {
  std::lock_guard lock(mu_);
  return port_.path();
}

std::string Pr650Endpoint::slave_path() const {
  std::lock_guard lock(mu_);
  return port_.slave_path();
}

void Pr650Endpoint::PowerCycle() {
  std::lock_guard lock(mu_);
  power_on_ = SteadyClock::now();
  ++power_epoch_;
  remote_ = false;
  standalone_ = false;
  setup_ = MeterSetup{};
  sync_ = false;
  last_setup_reply_ = 0;
  last_ = Measurement{};
  input_.clear();
  // Whatever was sent to the meter while it was off is lost.
  if (port_.is_open()) ::tcflush(port_.master_fd(), TCIFLUSH);
}

bool Pr650Endpoint::remote_mode() const {
  std::lock_guard lock(mu_);
  return remote_;
}

std::vector<std::string> Pr650Endpoint::commands() const {
  std::lock_guard lock(mu_);
  return commands_;
}

std::vector<MeterSetup> Pr650Endpoint::measured_setups() const {
  std::lock_guard lock(mu_);
  return measured_setups_;
}

bool Pr650Endpoint::SleepReal(std::chrono::nanoseconds d) {
  return SleepUnlessStopped(d, stop_);
}

void Pr650Endpoint::Run() {
  while (!stop_) {
    int fd = -1;
    {
      std::lock_guard lock(mu_);
      fd = port_.master_fd();
    }
    if (fd < 0) {
      SleepReal(kSlice);
      continue;
    }
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(kSlice.count())) <= 0) continue;
    char buffer[512];
    const ssize_t n = (p.revents & POLLIN) ? ::read(fd, buffer, sizeof buffer) : -1;
    if (n <= 0) {
      // No reader on the slave side for a moment (cannot happen while the keep-alive slave
      // descriptor is open, but never spin).
      SleepReal(kSlice);
      continue;
    }
    std::vector<std::string> complete;
    {
      std::lock_guard lock(mu_);
      for (ssize_t i = 0; i < n; ++i) {
        const char c = buffer[i];
        if (c == '\r' || c == '\n') {
          std::string command = TrimBlanks(input_);
          input_.clear();
          if (!command.empty()) complete.push_back(UpperAscii(command));
        } else if (input_.size() < 256) {
          input_.push_back(c);
        }
      }
    }
    for (const std::string& command : complete) {
      if (stop_) break;
      Handle(command);
    }
  }
}

void Pr650Endpoint::Handle(const std::string& command) {
  unsigned epoch = 0;
  if (!Admit(command, epoch)) return;
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
    std::snprintf(text, sizeof text, "00,%.1f", options_.flicker_hz);
    Reply({text + options_.flicker_reply_suffix});
    return;
  }
  const std::optional<int> code = ResponseCode(command);
  if (!code.has_value()) return;  // unknown: the simulated meter does not answer
  if (command[0] == 'M' && (*code == 0 || IsServedReport(*code))) {
    HandleMeasure(*code, epoch);
    return;
  }
  if (command[0] != 'D') return;  // M7 … M98: not served
  HandleReport(*code);
}

bool Pr650Endpoint::Admit(const std::string& command, unsigned& epoch) {
  const SerialFaults faults = control_.serial();
  std::lock_guard lock(mu_);
  commands_.push_back(command);
  if (faults.silent) return false;
  if (!remote_) {
    const double since_power_on = options_.time_scale.ToSim(
        std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now() - power_on_));
    if (standalone_ || (options_.wake_window_s > 0 && since_power_on > options_.wake_window_s)) {
      standalone_ = true;  // first command too late: stand-alone until power-cycled
      return false;
    }
    remote_ = true;
  }
  epoch = power_epoch_;
  return true;
}

void Pr650Endpoint::HandleSetup(const std::string& command) {
  const Pr650SetupResult result = ApplyPr650Setup(std::string_view(command).substr(1));
  {
    std::lock_guard lock(mu_);
    last_setup_reply_ = result.reply_code;
    if (result.reply_code == 0) {
      setup_ = result.setup;
      sync_ = result.sync;
    }
  }
  char text[8];
  std::snprintf(text, sizeof text, "%02d", result.reply_code);
  Reply({text});
}

void Pr650Endpoint::HandleMeasure(int code, unsigned epoch) {
  // M0 measures and holds; Mn is M0 followed by report n, in one reply.
  const std::optional<int> quality_code = Measure(epoch);
  if (!quality_code.has_value()) return;
  if (code != 0) {
    ReplyReport(code);
    return;
  }
  const int status = options_.m0_reply_is_quality ? std::clamp(*quality_code, 0, 999) : 0;
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
    std::string serial = options_.serial_number.substr(0, 8);
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
    int reply = 0;
    {
      std::lock_guard lock(mu_);
      reply = last_setup_reply_;
    }
    char text[8];
    std::snprintf(text, sizeof text, "%02d", reply);
    Reply({text});
    return;
  }
  // Other response codes (D19's binary block, D111, ...): no source documents them for the
  // PR-650; the simulated meter does not answer.
}

std::optional<int> Pr650Endpoint::Measure(unsigned epoch) {
  MeterSetup setup;
  {
    std::lock_guard lock(mu_);
    setup = setup_;
    measured_setups_.push_back(setup);
  }
  SimMeasurement m = backend_.Measure(setup);
  const auto [forced, no_data] = control_.UpdateSerial([](SerialFaults& f) {
    int code = -1;
    if (f.quality_count > 0) {
      --f.quality_count;
      code = f.quality_code;
    }
    const bool none = f.no_data_next > 0;
    if (none) --f.no_data_next;
    return std::pair{code, none};
  });
  if (forced >= 0) m.quality_code = forced;
  if (!SleepReal(options_.time_scale.ToReal(std::max(0.0, m.duration_s)))) return std::nullopt;
  std::lock_guard lock(mu_);
  if (epoch != power_epoch_) return std::nullopt;  // switched off mid-measurement: no reply
  // A measurement that gave no data leaves nothing to report: the reports answer "-1".
  last_ = no_data ? Measurement{}
                  : Measurement{true, m.quality_code, m.integrated, std::move(m.radiance)};
  return m.quality_code;
}

void Pr650Endpoint::ReplyReport(int report) {
  Measurement last;
  {
    std::lock_guard lock(mu_);
    last = last_;
  }
  if (!last.valid) {
    Reply({kNoMeasurementReply});
    return;
  }
  const int units_code = control_.serial().units_code;
  if (report != 5) {
    Reply({Pr650ColorimetryLine(report, last.quality_code, units_code,
                                Pr650TristimulusOf(last.radiance))});
    return;
  }
  const double vanish = control_.UpdateSerial([](SerialFaults& f) {
    const double seconds = f.vanish_seconds;
    f.vanish_seconds = 0;
    return seconds;
  });
  Reply(Pr650SpectrumLines(last.quality_code, units_code, last.integrated, last.radiance), vanish);
}

void Pr650Endpoint::Reply(std::vector<std::string> lines, double vanish_seconds) {
  const Pr650WireQuirks& q = options_.quirks;
  const auto [garble, truncate] = control_.UpdateSerial([](SerialFaults& f) {
    const bool g = f.garbage_next > 0;
    const bool t = !g && f.truncate_next > 0;
    if (g) --f.garbage_next;
    if (t) --f.truncate_next;
    return std::pair{g, t};
  });

  const char* eol = q.line_ending == Pr650WireQuirks::LineEnding::kLf   ? "\n"
                    : q.line_ending == Pr650WireQuirks::LineEnding::kCr ? "\r"
                                                                        : "\r\n";
  std::string bytes;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string line = garble ? GarbleLine(lines[i], static_cast<unsigned>(i)) : lines[i];
    bytes += line;
    const bool bare_cr = q.d5_header_bare_cr && i == 0 && lines.size() > 2;
    bytes += bare_cr ? "\r" : eol;
  }
  if (truncate) bytes.resize(bytes.size() / 2);

  const bool delayed = q.delayed_replies == 0 || replies_sent_ < q.delayed_replies;
  ++replies_sent_;
  if (delayed && q.reply_delay.count() > 0 && !SleepReal(q.reply_delay)) return;
  if (vanish_seconds > 0) {
    // Part of the report goes out, then the port is gone.
    if (!WriteOut(bytes.substr(0, bytes.size() / 3))) return;
    Vanish(vanish_seconds);
    return;
  }
  WriteOut(bytes);
}

bool Pr650Endpoint::WriteOut(const std::string& bytes) {
  int fd = -1;
  {
    std::lock_guard lock(mu_);
    fd = port_.master_fd();
  }
  const Pr650WireQuirks& q = options_.quirks;
  const WirePace pace{options_.time_scale, options_.pace_replies, options_.baud,
                      options_.fifo_bytes, q.piece_bytes,         q.piece_gap};
  return WriteWire(fd, bytes, pace, stop_);
}

void Pr650Endpoint::Vanish(double seconds) {
  {
    std::lock_guard lock(mu_);
    port_.Unplug();
    input_.clear();
  }
  if (!SleepReal(options_.time_scale.ToReal(seconds))) return;
  std::lock_guard lock(mu_);
  // The meter itself stayed on: it is still in remote mode and still holds its measurement.
  port_.Replug();
}

}  // namespace brdf::sim
