// The simulated PR-650 on a pseudo-terminal: a LineMeterEndpoint (meter/endpoint.h: the pty, its
// thread, the faults, paced replies) that speaks the meter's remote-mode protocol (docs/pr650.md)
// byte for byte, asking a MeterBackend what it would measure.
//
//   commands (case-insensitive, ended by CR or LF)     replies (lines end CR LF)
//   B0 … B3                                             000
//   S<acc1>,<acc2>,<acc3>,<acc4>,<sync>,<integ>,<avg>,<units>   pp (00 ok, 01–08 bad field, 09 too
//                                                       many fields, 50 accessory not fitted);
//                                                       "S" alone keeps the defaults (00)
//   F                                                   qq,freq  ("00,100.0"; flicker_reply_suffix
//                                                       appended)
//   M0                                                  000 once the measurement is done (its
//                                                       quality is in the reports); with
//                                                       m0_reply_is_quality the quality code
//                                                       itself ("018"), brdf-sim's older reply
//   D1                                                  qq,U,Y.YYYEsee,.xxxx,.yyyy  (Y, x, y)
//   D2                                                  qq,U,X.XXXEsee,Y.YYYEsee,Z.ZZZEsee
//   D3                                                  qq,U,Y.YYYEsee,.uuuu,.vvvv  (Y, u', v')
//   D4                                                  qq,U,Y.YYYEsee,T.TTTEsee,+.dddd (Y, CCT
//                                                       in K, deviation from the locus)
//   D5                                                  qq,U / integrated / 101 × "0380.,r.rrrEsee"
//   D6                                                  qq,U,Y.YYYEsee,.xxxx,.yyyy,.uuuu,.vvvv
//   M1 … M6 (M alone: M1)                               a measurement, then report 1 … 6 as its
//                                                       reply (also after a bad quality code)
//   D110                                                the serial number, blank-padded to 8
//   D120                                                0101,008.0,0380.,0780.,004.
//   D201                                                the last S command's reply pp again (00
//                                                       before any)
//   anything else (M19, D111, E, ...)                   no reply: no source documents them
// Response codes are read by value, so "M01" is M1 and "D05" is D5 (one source writes M01).
//
// A report asked for before any measurement since power-on (D1–D6), or after a measurement that
// gave no data (SerialFaults::no_data_next), is answered with the status line "-1" alone
// (kNoMeasurementReply), the value the open programs treat as "no data"; the meter never sends
// a spectrum it has not measured. The reports carry SerialFaults::units_code (0 unless set).
// Remote mode starts only if the first command arrives within wake_window_s (simulated) of
// power-on (Start or PowerCycle); otherwise the meter stays in stand-alone mode and answers
// nothing until power-cycled (as after the leave-remote fault, which takes the meter out of
// remote mode outside the window). Faults come from SimControl::serial() at each command; the
// "next N" counters are counted down through SimControl::UpdateSerial.
//
// The port path is a stable symlink to the current pty slave (path()). When the port "vanishes"
// (SerialFaults::vanish_seconds, during the next D5 or M5 report) the pty is closed (a driver
// holding it sees a hang-up, EIO), the link is removed, and after the pause a new pty is made and
// the link points at it. The new pty usually has a different /dev/pts number, so drivers must open
// the link path, and reopen it by name after a disconnect (the PR-650 driver does).
#pragma once

#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "core/status.h"
#include "tools/brdf-sim/meter/endpoint.h"
#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

// Ways real meters and USB adapters deliver replies that a driver must cope with. The defaults are
// the meter's own: CR LF, one write per reply, no delay.
struct Pr650WireQuirks {
  enum class LineEnding { kCrLf, kLf, kCr };
  LineEnding line_ending = LineEnding::kCrLf;
  // D5 header and integrated line run together with a bare CR ("00,0\r1.234E+01\r\n"), as one
  // quoted manual line shows.
  bool d5_header_bare_cr = false;
  // > 0: replies leave in pieces of this many bytes, piece_gap apart (real time).
  int piece_bytes = 0;
  std::chrono::milliseconds piece_gap{0};
  // Real-time delay before each reply starts ...
  std::chrono::milliseconds reply_delay{0};
  // ... or, when > 0, before the first this many replies only (a meter slow once, say while it
  // wakes, whose late reply a driver must not take for the next command's).
  int delayed_replies = 0;
};

struct Pr650EndpointOptions {
  TimeScale time_scale;
  // Simulated seconds after power-on within which the first command enters remote mode (the
  // meter's ~5 s); 0 = always.
  double wake_window_s = 5.0;
  // Send reply bytes at the serial rate (baud / 10 bytes per simulated second), so a D5 takes
  // ~1.8 s simulated like the real meter; off: as fast as the pty takes them.
  bool pace_replies = false;
  int baud = 9600;
  // With pace_replies: bytes reach the computer in bursts of this many, each once its last byte
  // is due, as a UART's receive FIFO (a 16550 interrupts at 14) or a USB-serial adapter hands
  // them over; the end of a reply (or piece) as soon as it is due. 1: byte by byte. The pace on
  // the wire is the same; the reader (and this thread) wake once per burst instead of per byte.
  int fifo_bytes = 14;
  // Where the stable port link goes; empty: a private temporary directory.
  std::string link_path;
  std::string serial_number = "60925301";
  double flicker_hz = 100.0;  // what F reports (a 50 Hz mains lamp flickers at 100 Hz)
  // Text after "qq,freq" in F's reply (" Hz", ",x"): a meter or adapter that adds to the reply.
  std::string flicker_reply_suffix;
  // M0 answers with the quality code ("018") instead of the meter's "000": what brdf-sim did
  // before it followed the meter, for drivers that judge the quality from M0's reply.
  bool m0_reply_is_quality = false;
  Pr650WireQuirks quirks;
};

// The reply to a report asked for before any measurement.
inline constexpr const char* kNoMeasurementReply = "-1";

class Pr650Endpoint final : public LineMeterEndpoint {
 public:
  Pr650Endpoint(MeterBackend& backend, SimControl& control, Pr650EndpointOptions options = {});
  ~Pr650Endpoint() override;
  // Start, Stop, path (brdf-sim prints it as "pr650 <path>"), slave_path, PowerCycle (the meter
  // also leaves remote mode and the wake-up window starts again), remote_mode, commands and
  // measured_setups: LineMeterEndpoint's.

 private:
  using SteadyClock = std::chrono::steady_clock;

  struct Measurement {
    bool valid = false;
    int quality_code = 0;
    double integrated = 0;
    std::vector<double> radiance;
  };

  void OnPowerOn() override;
  void OnCharacter(char c) override;
  void Handle(const std::string& command) override;
  // The D5 header and integrated line run together with a bare CR (Pr650WireQuirks).
  std::string LineEnd(std::size_t line, std::size_t count) const override;
  // What a power-on made the meter forget (its setup, measurement, stand-alone mode and the
  // command being typed), forgotten on the endpoint thread before the next character.
  void ForgetIfSwitchedOff();
  // Notes the command; false when the meter does not answer it (a fault, or stand-alone: the
  // first command came after the wake window).
  bool AdmitCommand(const std::string& command);
  // S: applies the setup and replies with its code.
  void HandleSetup(const std::string& command);
  // M0 measures and holds; Mn (n a served report) is M0 followed by report n, in one reply.
  void HandleMeasure(int code);
  // Dn: a served report, the serial number (110), the layout (120) or the last S reply (201).
  void HandleReport(int code);
  // Takes a measurement (its simulated duration in real time) into last_ and returns its quality
  // code; nullopt if stopped or switched off meanwhile (no reply then).
  std::optional<int> Measure();
  // Report 1, 2, 3 or 5 of last_ (the D5 report with the vanish fault, if armed), or
  // kNoMeasurementReply when there is none.
  void ReplyReport(int report);

  const Pr650EndpointOptions pr650_;
  std::atomic<SteadyClock::rep> power_on_{0};  // SteadyClock ticks at the last power-on
  std::atomic<bool> forget_{false};            // set by OnPowerOn, acted on by the thread

  // The endpoint thread's own:
  bool standalone_ = false;  // the wake-up window was missed: silent until power-cycled
  MeterSetup setup_;
  bool sync_ = false;
  int last_setup_reply_ = 0;  // the last S command's reply code, for D201
  Measurement last_;
};

}  // namespace brdf::sim
