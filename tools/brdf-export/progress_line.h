// The progress of a long export on standard error: on a terminal one line redrawn in place
//   brdf-export merl: 42.0 %  ETA 0:31
// at most ten times a second; otherwise (a log, a pipe) one line per 10 %.
#pragma once

#include <chrono>
#include <ostream>
#include <string>

namespace brdf::export_tool {

class ProgressLine {
 public:
  ProgressLine(std::ostream& out, std::string label, bool terminal);
  // A fraction in [0, 1] (non-decreasing), as exports::ProgressFn delivers it.
  void Update(double fraction);
  // Ends the line (if one is drawn).
  void Finish();

 private:
  std::ostream& out_;
  std::string label_;
  bool terminal_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_{};
  int last_decile_ = -1;
  bool drawn_ = false;
};

// "0:31", "1:02:05".
std::string FormatDuration(double seconds);

}  // namespace brdf::export_tool
