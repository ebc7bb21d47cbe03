#include "tools/brdf-interp/tool_common.h"

#include <charconv>
#include <cmath>

#include "core/interp/octant/reference.h"

namespace brdf::interp_tool {

int ExitCodeFor(const Status& status) {
  if (status.ok()) return kExitOk;
  return status.code() == StatusCode::kInvalidArgument ? kExitUsage : kExitFailure;
}

const std::vector<std::string>& MethodChoices() {
  static const std::vector<std::string> kChoices = {"octant", "octant-reference", "delaunay",
                                                    "nearest"};
  return kChoices;
}

Result<std::unique_ptr<interp::Interpolator>> MakeNamedInterpolator(
    const std::string& method, std::shared_ptr<const interp::SampleSet> samples,
    const interp::Options& options) {
  if (method == "octant-reference") {
    if (options.trend != interp::Trend::kNone) {
      return InvalidArgument(
          "--trend: octant-reference is the paper's method as published; use "
          "--method octant with a trend");
    }
    return interp::MakeOctantReferenceInterpolator(std::move(samples), options);
  }
  BRDF_ASSIGN_OR_RETURN(interp::Method m, interp::ParseMethod(method));
  return interp::MakeInterpolator(m, std::move(samples), options);
}

Result<std::vector<double>> ParseNumberList(const std::string& text, const std::string& option) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t comma = text.find(',', pos);
    const std::string item =
        text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    double value = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || end != item.data() + item.size() ||
        !std::isfinite(value)) {
      return InvalidArgument(option + ": '" + item + "' in '" + text +
                             "' is not a number; give comma-separated numbers, e.g. 1,1,0.5");
    }
    out.push_back(value);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

}  // namespace brdf::interp_tool
