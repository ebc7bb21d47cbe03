// The one-line progress display of `brdfctl watch` on a terminal, as a pure function of what the
// watcher knows, so that it can be tested without a terminal:
//   running [##########··········] 45/120 37%  ETA 0:42  α 20° β −30° γ 0° δ 22.5°  q 0
// Parts are dropped from the right (quality, pose, then the bar) when the terminal is narrow.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

struct ProgressView {
  std::string state;  // "running", "awaiting_operator", …
  std::uint32_t done_steps = 0;
  std::uint32_t total_steps = 0;
  double eta_s = -1;             // < 0: not known
  std::optional<v1::Pose> pose;  // the pose of the latest reading
  int quality_code = -1;         // the meter's last quality code; < 0: none yet
};

// Columns `text` takes on a terminal (UTF-8 code points; every one counted as one column).
std::size_t DisplayWidth(const std::string& text);

// The line for a terminal `width` columns wide (never wider; at least the counts are shown).
std::string RenderProgressLine(const ProgressView& view, int width);

}  // namespace brdf::ctl
