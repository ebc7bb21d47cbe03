#include "core/export/fill/uncertainty_summary.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/export/fill/uncertain_chain.h"
#include "core/export/grid/regular_grid.h"
#include "core/export/number_text.h"
#include "core/json_text.h"

namespace brdf::exports {
namespace {

constexpr double kSummaryStepDeg = 5.0;

// The q-quantile (0 ≤ q ≤ 1, nearest rank) of `v` (reordered); NaN when empty.
double Quantile(std::vector<double>& v, double q) {
  if (v.empty()) return std::nan("");
  const auto k = static_cast<std::size_t>(std::round(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

std::string Numbers(const std::vector<double>& values) {
  std::string j = "[";
  for (std::size_t k = 0; k < values.size(); ++k) {
    j += (k ? ", " : "") + (std::isfinite(values[k]) ? FormatNumber(values[k]) : "null");
  }
  return j + "]";
}

// {"median": [per band], "p95": [per band]} of plane `u` relative to the values, over the cells
// where both are finite and the value is positive.
std::string RelativeSummary(const MemoryGrid& values, const MemoryGrid& u) {
  const std::size_t bands = values.bands().count;
  std::vector<double> median(bands), p95(bands), rel;
  for (std::size_t b = 0; b < bands; ++b) {
    rel.clear();
    for (std::size_t c = 0; c < values.statuses().size(); ++c) {
      const double f = values.values()[c * bands + b];
      const double s = u.values()[c * bands + b];
      if (std::isfinite(f) && f > 0 && std::isfinite(s)) rel.push_back(s / f);
    }
    median[b] = Quantile(rel, 0.5);
    p95[b] = Quantile(rel, 0.95);
  }
  return "{\"median\": " + Numbers(median) + ", \"p95\": " + Numbers(p95) + "}";
}

// The white standard's relative part per band (the median over the samples' budgets of
// |u_white| / f): the same in every cell, since all readings share it.
std::vector<double> WhiteStandardPart(const DerivedSamples& derived) {
  const std::size_t bands = derived.grid.count;
  std::vector<double> out(bands, std::nan("")), rel;
  for (std::size_t b = 0; b < bands; ++b) {
    rel.clear();
    for (const DerivedSample& s : derived.samples) {
      const std::vector<double>* w = s.budget ? &s.budget->white_standard : nullptr;
      if (w == nullptr || b >= w->size() || b >= s.values.size() || s.values[b] <= 0) continue;
      rel.push_back(std::abs((*w)[b]) / s.values[b]);
    }
    out[b] = Quantile(rel, 0.5);
  }
  return out;
}

}  // namespace

Result<std::string> UncertaintySummaryJson(const SessionInterpolant& in, const std::string& format,
                                           const RunControl& control, const CallContext& ctx) {
  const UncertainChain uncertain = MakeUncertainChain(in);
  BRDF_ASSIGN_OR_RETURN(RegularGrid grid,
                        MakeRegularGrid(kSummaryStepDeg, kSummaryStepDeg, kSummaryStepDeg,
                                        GridPlacement::kCellCentres));
  MemoryGrid planes[kUncertainPlanes];
  PlaneSplitSink split({&planes[0], &planes[1], &planes[2], &planes[3]});
  BRDF_ASSIGN_OR_RETURN(GridReport report,
                        ResampleOnGrid(uncertain.chain->Source(), grid, in.derived->grid, control,
                                       ctx, split, kUncertainPlanes));
  const WavelengthGrid& bands = in.derived->grid;
  std::string j =
      "{\n  \"format\": " + JsonString(format) +
      ",\n  \"what\": \"the uncertainty of the export's cells, which the format "
      "cannot hold: per band, the median and 95th percentile of the relative standard "
      "uncertainty (u / f, k = 1) over the cells of a 5-degree (theta_i, theta_o, "
      "phi) grid of the hemisphere, answered as the export's cells are (the same "
      "interpolation, fill chain and uncertainty as a grid export with uncertainty)\",\n";
  j += "  \"k\": 1,\n  \"wavelength_nm\": {\"start\": " + FormatNumber(bands.start_nm) +
       ", \"step\": " + FormatNumber(bands.step_nm) +
       ", \"count\": " + std::to_string(bands.count) + "},\n";
  j += "  \"cells_summarised\": " + std::to_string(report.filled) + ",\n";
  j += "  \"relative_u\": " + RelativeSummary(planes[0], planes[1]) + ",\n";
  j += "  \"relative_u_measurement\": " + RelativeSummary(planes[0], planes[2]) + ",\n";
  j += "  \"relative_u_interpolation\": " + RelativeSummary(planes[0], planes[3]) + ",\n";
  j += "  \"relative_white_standard\": " + Numbers(WhiteStandardPart(*in.derived)) + ",\n";
  j += "  \"coverage\": " + UncertaintyJson(uncertain.coverage, in.derived->quantity, {}) + "\n}\n";
  return j;
}

}  // namespace brdf::exports
