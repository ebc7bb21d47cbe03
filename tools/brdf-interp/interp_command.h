// `brdf-interp SAMPLES.csv QUERIES.csv`: interpolate every query, write the output CSV
// (output_csv.h) to a file or standard output, and a one-line summary to `err`.
#pragma once

#include <ostream>
#include <string>

namespace brdf::interp_tool {

struct InterpRequest {
  std::string samples_path;
  std::string queries_path;
  std::string output_path;  // "" or "-": standard output
  std::string method = "octant";
  int threads = 1;
  std::string scale;  // "a,b,c[,d]" or ""
  bool mirror_phi = false;
  bool reciprocity = false;
  std::string coordinates = "incidence";  // or "half-diff" (interp::ParseCoordinates)
  std::string trend = "none";             // or "bivariate" (interp::ParseTrend)
  bool explain = false;
};

// Returns the process exit code (tool_common.h); messages name the file, line and column.
int RunInterp(const InterpRequest& request, std::ostream& err);

}  // namespace brdf::interp_tool
