#include "core/export/fill/uncertain_grid.h"

#include <utility>

namespace brdf::exports {

std::string CompanionFileName(const std::string& file, const std::string& part,
                              const std::string& extension) {
  const std::size_t dot = file.rfind('.');
  const std::string stem = dot == std::string::npos ? file : file.substr(0, dot);
  const std::string ext = dot == std::string::npos ? "" : file.substr(dot);
  return stem + "." + part + (extension.empty() ? ext : extension);
}

std::vector<UncertaintyFile> UncertaintyFiles(const std::string& file) {
  std::vector<UncertaintyFile> files;
  for (UncertainPlane plane : kUncertaintyArrays) {
    files.push_back({plane, CompanionFileName(file, UncertainPlaneName(plane))});
  }
  return files;
}

Result<UncertainGrid> ResampleWithUncertainty(const SessionInterpolant& in, const RegularGrid& grid,
                                              Quantity quantity, const RunControl& control,
                                              const CallContext& ctx, GridSink& values,
                                              const std::array<GridSink*, 3>& arrays,
                                              const std::string& file) {
  const UncertainChain uncertain = MakeUncertainChain(in);
  PlaneSplitSink split({&values, arrays[0], arrays[1], arrays[2]});
  UncertainGrid out;
  BRDF_ASSIGN_OR_RETURN(
      out.report, ResampleOnGrid(uncertain.chain->Source(), grid, in.derived->grid, control, ctx,
                                 split, kUncertainPlanes));
  out.tally = uncertain.chain->Tally();
  out.uncertainty_json = UncertaintyJson(uncertain.coverage, quantity, UncertaintyFiles(file));
  out.warnings = UncertaintyWarnings(uncertain.coverage);
  return out;
}

}  // namespace brdf::exports
