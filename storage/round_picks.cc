#include "storage/round_picks.h"

#include <cstdio>
#include <sstream>

namespace brdf::storage {

std::string EncodePicks(const std::vector<RoundPick>& picks) {
  std::string out;
  char line[160];
  for (const RoundPick& p : picks) {
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g %.17g %.17g\n", p.pose.alpha, p.pose.beta,
                  p.pose.gamma, p.pose.delta, p.predicted_gain);
    out += line;
  }
  return out;
}

Result<std::vector<RoundPick>> DecodePicks(std::string_view text) {
  std::vector<RoundPick> out;
  std::istringstream in{std::string(text)};
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::istringstream fields(line);
    RoundPick p;
    if (!(fields >> p.pose.alpha >> p.pose.beta >> p.pose.gamma >> p.pose.delta >>
          p.predicted_gain)) {
      return InvalidArgument("adaptive_rounds.picks line " + std::to_string(number) + " (\"" +
                             line + "\") is not five numbers \"alpha beta gamma delta gain\"");
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace brdf::storage
