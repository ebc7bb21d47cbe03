// The simulated meters' serial endpoints, as brdf-sim's main and the control unit see them
// (MeterPort), and what every one of them shares (LineMeterEndpoint): a pseudo-terminal behind a
// stable link (meter/pr650_pty.h), a thread that reads the characters a driver types, remote
// mode, the injected faults (silence, leaving remote mode, garbage, truncation, a vanishing port,
// forced codes), and replies written at the serial rate, delayed or in pieces as some meters and
// adapters send them. A derived endpoint speaks its meter's protocol (meter/pr650_endpoint.h,
// meter/pr670_endpoint.h, meter/cs2000_endpoint.h).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/status.h"
#include "tools/brdf-sim/meter/pr650_pty.h"
#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

// One simulated meter on a pty, whatever its protocol.
class MeterPort {
 public:
  virtual ~MeterPort() = default;
  // Creates the pty and the link, powers the meter on and starts serving.
  virtual Status Start() = 0;
  // Stops serving and removes the pty and the link. Idempotent.
  virtual void Stop() = 0;
  // The path drivers open: the stable link.
  virtual std::string path() const = 0;
  // The current pty slave (/dev/pts/N); changes when the port vanishes and comes back.
  virtual std::string slave_path() const = 0;
  // Switches the meter off and on: it leaves remote mode and forgets its setup and measurement.
  virtual void PowerCycle() = 0;
};

struct LineEndpointOptions {
  TimeScale time_scale;
  bool pace_replies = false;  // at `baud` (a USB CDC meter is not paced by a baud rate)
  int baud = 9600;
  int fifo_bytes = 14;
  std::string link_path;      // where the stable link goes; empty: a private temp directory
  std::string eol = "\r\n";   // what ends each reply line
  std::string serial_number;  // what the meter reports as its serial number
  // How replies leave, as some meters and USB adapters deliver them (a driver must cope):
  int piece_bytes = 0;  // > 0: in pieces of this many bytes, piece_gap (real time) apart
  std::chrono::milliseconds piece_gap{0};
  std::chrono::milliseconds reply_delay{0};  // real time before each reply starts ...
  int delayed_replies = 0;  // ... or, when > 0, before the first this many replies only
};

class LineMeterEndpoint : public MeterPort {
 public:
  LineMeterEndpoint(MeterBackend& backend, SimControl& control, LineEndpointOptions options);
  // A derived endpoint calls Stop() in its own destructor, before its members go.
  ~LineMeterEndpoint() override;
  LineMeterEndpoint(const LineMeterEndpoint&) = delete;
  LineMeterEndpoint& operator=(const LineMeterEndpoint&) = delete;

  Status Start() override;
  void Stop() override;
  std::string path() const override;
  std::string slave_path() const override;
  void PowerCycle() override;

  bool remote_mode() const;
  // Every command received so far, upper-cased, without its line end (also those not answered).
  std::vector<std::string> commands() const;
  // Setups the backend has been asked to measure with, in order.
  std::vector<MeterSetup> measured_setups() const;

 protected:
  // One measurement as the meter took it: what the optics saw, the code the fault forces (the
  // meter's own code, SerialFaults::quality_code) and whether it gave no data.
  struct Taken {
    SimMeasurement measurement;
    std::optional<int> forced_code;
    bool no_data = false;
  };

  // Each character received, in order, on the endpoint thread. The default collects a line and
  // hands it to Handle at its CR or LF; the PR-670's PHOTO and Q need no line end.
  virtual void OnCharacter(char c);
  // A complete command, trimmed and upper-cased.
  virtual void Handle(const std::string& command) = 0;
  // The meter is switched on (Start, PowerCycle), from the caller's thread: what it forgets (its
  // setup, its measurement), and when it woke.
  virtual void OnPowerOn() {}
  // What ends line `line` of a reply of `count` lines; options.eol unless a meter says otherwise.
  virtual std::string LineEnd(std::size_t line, std::size_t count) const;

  // Notes `command` and says whether the meter answers it: not while the silent fault holds, not
  // outside remote mode unless `enters_remote`; the leave-remote fault takes effect here.
  bool Admit(const std::string& command, bool enters_remote);
  void SetRemote(bool on);
  // Measures `setup` with the backend, taking the measurement's simulated time; nullopt when the
  // endpoint stops or the meter is switched off meanwhile. `announce` (if set) sees the
  // measurement before its time passes (the CS-2000 announces its measuring time).
  std::optional<Taken> TakeMeasurement(const MeterSetup& setup,
                                       const std::function<void(const Taken&)>& announce = nullptr);
  // Sends `lines` as one reply, each ended by LineEnd, with the garbage and truncation faults
  // applied, after options.reply_delay; `vanish_seconds` > 0: the port vanishes a third of the
  // way through, back after that.
  void Reply(const std::vector<std::string>& lines, double vanish_seconds = 0);
  // The vanish fault, consumed (0 when not armed).
  double TakeVanish();
  // Sleeps `seconds` of simulated time; false if the endpoint stops meanwhile.
  bool SleepSim(double seconds);

  const LineEndpointOptions& options() const { return options_; }
  MeterBackend& backend_;
  SimControl& control_;
  std::string input_;  // the command being typed (endpoint thread only)

 private:
  void Run();
  bool WriteOut(const std::string& bytes);
  void Vanish(double seconds);

  const LineEndpointOptions options_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  int replies_sent_ = 0;  // for options.delayed_replies (endpoint thread only)

  mutable std::mutex mu_;  // guards everything below
  PtyPort port_;
  unsigned power_epoch_ = 0;
  bool remote_ = false;
  std::vector<std::string> commands_;
  std::vector<MeterSetup> measured_setups_;
};

}  // namespace brdf::sim
