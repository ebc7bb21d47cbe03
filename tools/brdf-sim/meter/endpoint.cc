#include "tools/brdf-sim/meter/endpoint.h"

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>

#include "tools/brdf-sim/meter/serial_wire.h"

namespace brdf::sim {

namespace {
constexpr auto kSlice = std::chrono::milliseconds(20);
}  // namespace

LineMeterEndpoint::LineMeterEndpoint(MeterBackend& backend, SimControl& control,
                                     LineEndpointOptions options)
    : backend_(backend), control_(control), options_(std::move(options)) {}

LineMeterEndpoint::~LineMeterEndpoint() {
  Stop();
}

Status LineMeterEndpoint::Start() {
  Stop();
  {
    std::lock_guard lock(mu_);
    BRDF_RETURN_IF_ERROR(port_.Open(options_.link_path));
    remote_ = false;
  }
  input_.clear();
  replies_sent_ = 0;
  OnPowerOn();
  stop_ = false;
  thread_ = std::thread([this] { Run(); });
  return Status::Ok();
}

void LineMeterEndpoint::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mu_);
  port_.Close();
}

std::string LineMeterEndpoint::path() const {
  std::lock_guard lock(mu_);
  return port_.path();
}

std::string LineMeterEndpoint::slave_path() const {
  std::lock_guard lock(mu_);
  return port_.slave_path();
}

void LineMeterEndpoint::PowerCycle() {
  {
    std::lock_guard lock(mu_);
    ++power_epoch_;
    remote_ = false;
    // Whatever was sent to the meter while it was off is lost.
    if (port_.is_open()) ::tcflush(port_.master_fd(), TCIFLUSH);
  }
  OnPowerOn();
}

bool LineMeterEndpoint::remote_mode() const {
  std::lock_guard lock(mu_);
  return remote_;
}

std::vector<std::string> LineMeterEndpoint::commands() const {
  std::lock_guard lock(mu_);
  return commands_;
}

std::vector<MeterSetup> LineMeterEndpoint::measured_setups() const {
  std::lock_guard lock(mu_);
  return measured_setups_;
}

void LineMeterEndpoint::SetRemote(bool on) {
  std::lock_guard lock(mu_);
  remote_ = on;
}

void LineMeterEndpoint::Run() {
  while (!stop_) {
    int fd = -1;
    {
      std::lock_guard lock(mu_);
      fd = port_.master_fd();
    }
    if (fd < 0) {
      SleepUnlessStopped(kSlice, stop_);
      continue;
    }
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(kSlice.count())) <= 0) continue;
    char buffer[512];
    const ssize_t n = (p.revents & POLLIN) ? ::read(fd, buffer, sizeof buffer) : -1;
    if (n <= 0) {
      SleepUnlessStopped(kSlice, stop_);
      continue;
    }
    for (ssize_t i = 0; i < n && !stop_; ++i) OnCharacter(buffer[i]);
  }
}

void LineMeterEndpoint::OnCharacter(char c) {
  if (c != '\r' && c != '\n') {
    if (input_.size() < 256) input_.push_back(c);
    return;
  }
  const std::string command = UpperAscii(TrimBlanks(input_));
  input_.clear();
  if (!command.empty()) Handle(command);
}

std::string LineMeterEndpoint::LineEnd(std::size_t, std::size_t) const {
  return options_.eol;
}

bool LineMeterEndpoint::Admit(const std::string& command, bool enters_remote) {
  const auto [silent, leave] = control_.UpdateSerial([](SerialFaults& f) {
    const bool leaving = f.leave_remote;
    f.leave_remote = false;
    return std::pair{f.silent, leaving};
  });
  std::lock_guard lock(mu_);
  commands_.push_back(command);
  if (leave) remote_ = false;  // the operator took the meter back: this command is lost
  if (silent || leave) return false;
  return remote_ || enters_remote;
}

std::optional<LineMeterEndpoint::Taken> LineMeterEndpoint::TakeMeasurement(
    const MeterSetup& setup, const std::function<void(const Taken&)>& announce) {
  unsigned epoch = 0;
  {
    std::lock_guard lock(mu_);
    epoch = power_epoch_;
    measured_setups_.push_back(setup);
  }
  Taken taken;
  taken.measurement = backend_.Measure(setup);
  control_.UpdateSerial([&](SerialFaults& f) {
    if (f.quality_count > 0) {
      --f.quality_count;
      taken.forced_code = f.quality_code;
    }
    if (f.no_data_next > 0) {
      --f.no_data_next;
      taken.no_data = true;
    }
  });
  if (announce) announce(taken);
  if (!SleepSim(std::max(0.0, taken.measurement.duration_s))) return std::nullopt;
  std::lock_guard lock(mu_);
  if (epoch != power_epoch_) return std::nullopt;  // switched off mid-measurement: no reply
  return taken;
}

bool LineMeterEndpoint::SleepSim(double seconds) {
  return SleepUnlessStopped(options_.time_scale.ToReal(seconds), stop_);
}

double LineMeterEndpoint::TakeVanish() {
  return control_.UpdateSerial([](SerialFaults& f) {
    const double seconds = f.vanish_seconds;
    f.vanish_seconds = 0;
    return seconds;
  });
}

void LineMeterEndpoint::Reply(const std::vector<std::string>& lines, double vanish_seconds) {
  const auto [garble, truncate] = control_.UpdateSerial([](SerialFaults& f) {
    const bool g = f.garbage_next > 0;
    const bool t = !g && f.truncate_next > 0;
    if (g) --f.garbage_next;
    if (t) --f.truncate_next;
    return std::pair{g, t};
  });
  std::string bytes;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    bytes += garble ? GarbleLine(lines[i], static_cast<unsigned>(i)) : lines[i];
    bytes += LineEnd(i, lines.size());
  }
  if (truncate) bytes.resize(bytes.size() / 2);
  const bool delayed = options_.delayed_replies == 0 || replies_sent_ < options_.delayed_replies;
  ++replies_sent_;
  if (delayed && options_.reply_delay.count() > 0 &&
      !SleepUnlessStopped(options_.reply_delay, stop_)) {
    return;
  }
  if (vanish_seconds > 0) {
    // Part of the reply goes out, then the port is gone.
    if (!WriteOut(bytes.substr(0, bytes.size() / 3))) return;
    Vanish(vanish_seconds);
    return;
  }
  WriteOut(bytes);
}

bool LineMeterEndpoint::WriteOut(const std::string& bytes) {
  int fd = -1;
  {
    std::lock_guard lock(mu_);
    fd = port_.master_fd();
  }
  const WirePace pace{options_.time_scale, options_.pace_replies, options_.baud,
                      options_.fifo_bytes, options_.piece_bytes,  options_.piece_gap};
  return WriteWire(fd, bytes, pace, stop_);
}

void LineMeterEndpoint::Vanish(double seconds) {
  {
    std::lock_guard lock(mu_);
    port_.Unplug();
  }
  input_.clear();
  if (!SleepSim(seconds)) return;
  std::lock_guard lock(mu_);
  // The meter itself stayed on: still in remote mode, still holding its measurement.
  port_.Replug();
}

}  // namespace brdf::sim
