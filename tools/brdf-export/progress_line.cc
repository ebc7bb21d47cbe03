#include "tools/brdf-export/progress_line.h"

#include <cmath>
#include <cstdio>
#include <utility>

namespace brdf::export_tool {

std::string FormatDuration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  }
  return buf;
}

ProgressLine::ProgressLine(std::ostream& out, std::string label, bool terminal)
    : out_(out),
      label_(std::move(label)),
      terminal_(terminal),
      start_(std::chrono::steady_clock::now()) {}

void ProgressLine::Update(double fraction) {
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  std::string eta = "";
  if (fraction > 0.01 && fraction < 1) {
    eta = "  ETA " + FormatDuration(elapsed * (1 - fraction) / fraction);
  }
  char pct[16];
  std::snprintf(pct, sizeof pct, "%5.1f %%", 100 * fraction);
  if (terminal_) {
    if (fraction < 1 && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    out_ << "\r" << label_ << ": " << pct << eta << "   " << std::flush;
    drawn_ = true;
    return;
  }
  const int decile = static_cast<int>(std::floor(fraction * 10 + 1e-9));
  if (decile <= last_decile_) return;
  last_decile_ = decile;
  out_ << label_ << ": " << pct << eta << "\n" << std::flush;
}

void ProgressLine::Finish() {
  if (terminal_ && drawn_) out_ << "\n" << std::flush;
  drawn_ = false;
}

}  // namespace brdf::export_tool
