#include "tools/brdfctl/watch/progress_line.h"

#include <algorithm>

#include "tools/brdfctl/output/text_format.h"

namespace brdf::ctl {

std::size_t DisplayWidth(const std::string& text) {
  std::size_t n = 0;
  for (unsigned char c : text) {
    if ((c & 0xC0) != 0x80) ++n;  // not a UTF-8 continuation byte
  }
  return n;
}

namespace {

std::string Bar(std::uint32_t done, std::uint32_t total, int cells) {
  const int filled =
      total == 0
          ? 0
          : static_cast<int>(static_cast<std::uint64_t>(std::min(done, total)) * cells / total);
  return "[" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(cells - filled), '-') + "]";
}

// Keeps the first `width` code points of `text`.
std::string Clip(const std::string& text, std::size_t width) {
  std::size_t points = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if ((c & 0xC0) != 0x80) {
      if (points == width) return text.substr(0, i);
      ++points;
    }
  }
  return text;
}

}  // namespace

std::string RenderProgressLine(const ProgressView& view, int width) {
  const std::size_t w = static_cast<std::size_t>(std::max(width, 20));
  std::string counts = std::to_string(view.done_steps) + "/" + std::to_string(view.total_steps);
  if (view.total_steps > 0) {
    counts +=
        " " +
        std::to_string(100ull * std::min(view.done_steps, view.total_steps) / view.total_steps) +
        "%";
  }
  const std::string eta = view.eta_s >= 0 ? "  ETA " + Duration(view.eta_s) : "";
  const std::string pose = view.pose ? "  " + PoseText(*view.pose) : "";
  const std::string quality =
      view.quality_code >= 0 ? "  q " + std::to_string(view.quality_code) : "";
  const std::string state = view.state.empty() ? "" : view.state + " ";

  // Widest first; drop the least important parts until the line fits.
  const std::string tails[] = {eta + pose + quality, eta + pose, eta, ""};
  for (const std::string& tail : tails) {
    const std::size_t fixed = DisplayWidth(state) + DisplayWidth(counts) + DisplayWidth(tail) + 1;
    if (fixed + 12 <= w) {  // room for a bar of at least 10 cells
      const int cells = static_cast<int>(std::min<std::size_t>(40, w - fixed - 2));
      return state + Bar(view.done_steps, view.total_steps, cells) + " " + counts + tail;
    }
  }
  return Clip(state + counts + eta, w);
}

}  // namespace brdf::ctl
