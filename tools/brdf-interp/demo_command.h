// `brdf-interp demo`: the paper's experiment offline. Builds the rig's sample-rotation grid
// (2,153 distinct points), "measures" the analytic paint-like sample there, interpolates one
// query between the samples and prints the answer: the blended vertices with their coordinates and
// weights, a summary of the spectrum, and its error against the analytic truth (with the nearest
// sample's error for scale).
#pragma once

#include <ostream>
#include <string>

namespace brdf::interp_tool {

struct DemoRequest {
  std::string method = "octant";
  std::string query;  // "θi,θo,φ"; "" for the built-in query
  std::string scale;
  bool mirror_phi = false;
  bool reciprocity = false;
  std::string coordinates = "incidence";  // or "half-diff"
  std::string trend = "none";             // or "bivariate" (interp::ParseTrend)
};

// The built-in query: between samples, inside the rig's range.
inline constexpr double kDemoQuery[3] = {37.0, 52.0, 128.0};

int RunDemo(const DemoRequest& request, std::ostream& out, std::ostream& err);

}  // namespace brdf::interp_tool
