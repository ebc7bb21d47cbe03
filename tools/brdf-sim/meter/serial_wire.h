// What every simulated meter's serial endpoint does on the wire, whatever its protocol: commands
// read case-insensitively, garbage of a reply's shape for the garbage fault, and replies written
// to the pty master at the serial rate (paced, in FIFO bursts, in pieces) or as fast as the pty
// takes them. Shared by the PR-650, PR-670 and CS-2000 endpoints.
#pragma once

#include <atomic>
#include <chrono>
#include <string>

#include "tools/brdf-sim/sim_shared.h"

namespace brdf::sim {

std::string UpperAscii(std::string s);
// `s` without leading and trailing blanks and tabs.
std::string TrimBlanks(const std::string& s);

// Junk of the same length as `line` (a complete-looking reply that does not parse: what a wrong
// baud rate or line noise gives); `seed` varies it by line.
std::string GarbleLine(const std::string& line, unsigned seed);

struct WirePace {
  TimeScale time_scale;
  bool pace = false;  // at the serial rate (baud / 10 bytes per simulated second)
  int baud = 9600;
  int fifo_bytes = 14;  // with pace: handed over in bursts of this many (a UART's FIFO)
  int piece_bytes = 0;  // > 0: in pieces of this many bytes, piece_gap (real time) apart
  std::chrono::milliseconds piece_gap{0};
};

// Writes `bytes` to the pty master `fd` as `pace` says. False if `stop` was set, the port went
// away, or nobody read for 2 s.
bool WriteWire(int fd, const std::string& bytes, const WirePace& pace,
               const std::atomic<bool>& stop);

// Sleeps `d` of real time in slices, unless `stop` is set meanwhile (then false).
bool SleepUnlessStopped(std::chrono::nanoseconds d, const std::atomic<bool>& stop);

}  // namespace brdf::sim
