#include "tools/brdfctl/output/rounds_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geometry.h"
#include "core/pose.h"
#include "tools/brdfctl/output/text_format.h"

namespace brdf::ctl {
namespace {

constexpr std::size_t kColumns = 80;
constexpr int kBarColumns = 50;

// Display columns of UTF-8 text (every character here is one column wide).
std::size_t Columns(const std::string& text) {
  return static_cast<std::size_t>(
      std::count_if(text.begin(), text.end(), [](char c) { return (c & 0xC0) != 0x80; }));
}

// The text cut to 80 columns, ending in "…" when cut.
std::string Fit(std::string text) {
  if (Columns(text) <= kColumns) return text;
  std::size_t columns = 0;
  std::size_t i = 0;
  for (; i < text.size(); ++i) {
    if ((text[i] & 0xC0) != 0x80 && ++columns == kColumns) break;
  }
  text.resize(i);
  return text + "…";
}

// "17:14 of 38:00 rig time" (the budget's limit when set).
std::string RigTimeOf(double seconds, const v1::AdaptiveBudget& budget) {
  std::string out = Duration(seconds);
  if (budget.max_rig_minutes() > 0) out += " of " + Duration(budget.max_rig_minutes() * 60);
  return out + " rig time";
}

// "31 of 60 prompts" (the budget's limit when set).
std::string CountOf(std::uint32_t count, std::uint32_t limit, const char* what) {
  std::string out = std::to_string(count);
  if (limit > 0) out += " of " + std::to_string(limit);
  return out + " " + what;
}

// "0°", "45°–78.75°": the round's δ range.
std::string DeltaRange(const v1::AdaptiveRound& r) {
  if (r.poses_size() == 0) return "-";
  double lo = r.poses(0).delta();
  double hi = lo;
  for (const v1::Pose& p : r.poses()) {
    lo = std::min(lo, p.delta());
    hi = std::max(hi, p.delta());
  }
  return lo == hi ? StageAngle(lo) + "°" : StageAngle(lo) + "°–" + StageAngle(hi) + "°";
}

// "  first poses: α 10° β −35° γ 0° δ 45°; …", as many as fit.
std::string FirstPoses(const v1::AdaptiveRound& r) {
  std::string line = "  first poses:";
  for (int i = 0; i < r.poses_size(); ++i) {
    const std::string more = (i == 0 ? " " : "; ") + PoseText(r.poses(i));
    if (Columns(line + more) > kColumns) break;
    line += more;
  }
  return line;
}

// The sample-fixed form: a pose is where the operator places lamp and detector, so its
// directions (the isotropic reduction, as the prompts give them) say more than the equivalent
// stage pose. From the round's directions (AdaptiveRound.directions), else from its poses.
IsoDirection DirectionsOf(const v1::AdaptiveRound& r, int i) {
  if (r.directions_size() == r.poses_size()) {
    const v1::Directions& d = r.directions(i);
    return ToIsotropic(Directions{d.theta_i(), d.phi_i(), d.theta_o(), d.phi_o()});
  }
  const v1::Pose& p = r.poses(i);
  return ToIsotropic(PoseToDirections(Pose{p.alpha(), p.beta(), p.gamma(), p.delta()}));
}

std::string IsoText(const IsoDirection& d) {
  return "θi " + StageAngle(d.theta_i) + "° θo " + StageAngle(d.theta_o) + "° φ " +
         StageAngle(d.phi) + "°";
}

// "  first directions: θi 50° θo 5° φ 130°; …", as many as fit.
std::string FirstDirections(const v1::AdaptiveRound& r) {
  std::string line = "  first directions:";
  for (int i = 0; i < r.poses_size(); ++i) {
    const std::string more = (i == 0 ? " " : "; ") + IsoText(DirectionsOf(r, i));
    if (Columns(line + more) > kColumns) break;
    line += more;
  }
  return line;
}

// "θi 25°–65°": the round's incidence range (the sample-fixed form's table column).
std::string ThetaIRange(const v1::AdaptiveRound& r) {
  if (r.poses_size() == 0) return "-";
  double lo = 90, hi = 0;
  for (int i = 0; i < r.poses_size(); ++i) {
    lo = std::min(lo, DirectionsOf(r, i).theta_i);
    hi = std::max(hi, DirectionsOf(r, i).theta_i);
  }
  return StageAngle(lo) == StageAngle(hi) ? StageAngle(lo) + "°"
                                          : StageAngle(lo) + "°–" + StageAngle(hi) + "°";
}

// "   3 0.277 ##############    |" : the uncertainty left as a bar, `scale` per column, the
// target's column marked.
std::string BarLine(const std::string& label, double left, double target, double scale) {
  const int filled = std::clamp(static_cast<int>(std::lround(left / scale)), 0, kBarColumns);
  const int mark =
      target > 0 ? std::clamp(static_cast<int>(std::lround(target / scale)), 0, kBarColumns) : -1;
  std::string bar;
  for (int c = 0; c <= kBarColumns; ++c) {
    if (c == mark) {
      bar += "|";
    } else if (c < filled) {
      bar += "#";
    } else if (c < mark) {
      bar += " ";
    }
  }
  char head[40];
  std::snprintf(head, sizeof head, "%6s %-7s ", label.c_str(), Num(left, 3).c_str());
  return head + bar;
}

}  // namespace

std::vector<std::string> WrapText(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t from = 0;
  while (from < text.size()) {
    std::size_t to = text.find(' ', from);
    if (to == std::string::npos) to = text.size();
    const std::string word = text.substr(from, to - from);
    from = to + 1;
    if (!line.empty() && Columns(line + " " + word) > kColumns) {
      lines.push_back(line);
      line = "  " + word;
    } else {
      line += (line.empty() ? "" : " ") + word;
    }
  }
  if (!line.empty()) lines.push_back(line);
  for (std::string& l : lines) l = Fit(l);
  return lines;
}

double TargetLevel(const v1::Adaptive& adaptive) {
  const v1::AdaptiveTarget& t = adaptive.target();
  if (t.has_expanded_uncertainty()) return t.expanded_uncertainty();
  if (t.has_expected_error()) return t.expected_error();
  return 0;
}

std::string AdaptiveGoalText(const v1::Adaptive& adaptive) {
  const v1::AdaptiveTarget& t = adaptive.target();
  std::string out = t.has_expected_error() ? "target expected error ≤ " : "target U (k = 2) ≤ ";
  out += Num(TargetLevel(adaptive), 3);
  const v1::AdaptiveBudget& b = adaptive.budget();
  std::vector<std::string> limits;
  if (b.max_readings() > 0) limits.push_back(std::to_string(b.max_readings()) + " readings");
  if (b.max_rig_minutes() > 0) limits.push_back(Duration(b.max_rig_minutes() * 60) + " rig time");
  if (b.max_prompts() > 0) limits.push_back(std::to_string(b.max_prompts()) + " prompts");
  for (std::size_t i = 0; i < limits.size(); ++i) out += (i == 0 ? "; budget " : ", ") + limits[i];
  return Fit(out);
}

std::string DeltaPathText(const v1::AdaptiveRound& r) {
  std::string out;
  for (int i = 0; i < r.poses_size(); ++i) {
    if (i > 0 && r.poses(i).delta() == r.poses(i - 1).delta()) continue;
    out += (out.empty() ? "δ " : " → ") + StageAngle(r.poses(i).delta()) + "°";
  }
  return out;
}

std::string RoundsSoFarText(const std::vector<v1::AdaptiveRound>& rounds) {
  const std::string head = std::to_string(rounds.size()) + " round(s) so far; uncertainty left ";
  std::string values;
  for (auto r = rounds.rbegin(); r != rounds.rend(); ++r) {
    const std::string more = Num(r->uncertainty_left(), 3) + (values.empty() ? "" : " → ");
    if (Columns(head + "… → " + more + values) > kColumns) return head + "… → " + values;
    values = more + values;
  }
  return head + values;
}

std::vector<std::string> AdaptiveRoundLines(const v1::AdaptiveRound& r,
                                            const v1::Adaptive& adaptive) {
  const v1::AdaptiveBudget& b = adaptive.budget();
  std::vector<std::string> lines;
  lines.push_back(Fit("round " + std::to_string(r.round()) + " (from " +
                      CountOf(r.readings_used(), b.max_readings(), "readings") +
                      "): uncertainty left " + Num(r.uncertainty_left(), 3) + ", target " +
                      Num(TargetLevel(adaptive), 3)));
  lines.push_back(Fit("  spent " + RigTimeOf(r.spent_rig_s(), b) + ", " +
                      CountOf(r.spent_prompts(), b.max_prompts(), "prompts") + "; predicted gain " +
                      Num(r.predicted_gain(), 3)));
  const std::uint32_t last = r.first_step() + std::max<std::uint32_t>(r.step_count(), 1) - 1;
  lines.push_back(Fit("  next: " + std::to_string(r.poses_size()) + " poses, steps " +
                      std::to_string(r.first_step()) + "–" + std::to_string(last) + ", +" +
                      Duration(r.rig_s()) + " rig time, +" + std::to_string(r.prompts()) +
                      " prompts"));
  if (r.poses_size() > 0 && adaptive.has_sample_fixed()) {
    lines.push_back(Fit(FirstDirections(r)));
  } else if (r.poses_size() > 0) {
    lines.push_back(Fit("  " + DeltaPathText(r)));
    lines.push_back(FirstPoses(r));
  }
  return lines;
}

std::vector<std::string> AdaptiveStopLines(const v1::AdaptiveStop& s,
                                           const v1::Adaptive& adaptive) {
  const v1::AdaptiveBudget& b = adaptive.budget();
  std::vector<std::string> lines = {Fit("adaptive stop: " + s.reason() + "; uncertainty left " +
                                        Num(s.uncertainty_left(), 3) + " (target " +
                                        Num(TargetLevel(adaptive), 3) + ")")};
  const std::string pieces[] = {CountOf(s.readings(), b.max_readings(), "readings"),
                                RigTimeOf(s.rig_s(), b),
                                CountOf(s.prompts(), b.max_prompts(), "prompts")};
  std::string line = "  after " + std::to_string(s.rounds()) + " round(s): " + pieces[0];
  for (std::size_t i = 1; i < std::size(pieces); ++i) {
    if (Columns(line + ", " + pieces[i]) > kColumns) {
      lines.push_back(line + ",");
      line = "  " + pieces[i];
    } else {
      line += ", " + pieces[i];
    }
  }
  lines.push_back(Fit(line));
  return lines;
}

void PrintRoundsTable(std::ostream& out, const std::vector<v1::AdaptiveRound>& rounds,
                      const v1::Adaptive& adaptive) {
  out << AdaptiveGoalText(adaptive) << "\n";
  if (rounds.empty()) {
    out << "no round yet (the seed design is measured first)\n";
    return;
  }
  const bool fixed = adaptive.has_sample_fixed();
  out << "round  readings  left     gain      rig time  prompts  poses  " << (fixed ? "θi" : "δ")
      << "\n";
  double highest = TargetLevel(adaptive);
  for (const v1::AdaptiveRound& r : rounds) {
    char row[160];
    std::snprintf(row, sizeof row, "%5u  %8u  %-7s  %-8s  %8s  %7u  %5d  %s", r.round(),
                  r.readings_used(), Num(r.uncertainty_left(), 3).c_str(),
                  Num(r.predicted_gain(), 3).c_str(), Duration(r.spent_rig_s()).c_str(),
                  r.spent_prompts(), r.poses_size(),
                  (fixed ? ThetaIRange(r) : DeltaRange(r)).c_str());
    out << Fit(row) << "\n";
    highest = std::max(highest, r.uncertainty_left());
  }
  out << "\nuncertainty left before each round (| the target):\n";
  const double scale = highest > 0 ? highest / kBarColumns : 1;
  for (const v1::AdaptiveRound& r : rounds) {
    out << BarLine(std::to_string(r.round()), r.uncertainty_left(), TargetLevel(adaptive), scale)
        << "\n";
  }
  out << "\nthe last round:\n";
  for (const std::string& line : AdaptiveRoundLines(rounds.back(), adaptive)) out << line << "\n";
}

}  // namespace brdf::ctl
