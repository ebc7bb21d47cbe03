// How `brdfctl readings` shows a reading's uncertainty (Reading.uncertainty, docs/uncertainty.md):
// expanded uncertainties U = k · u_c of its BRDF, k the coverage factor (--k, default 2: about
// 95 % for a near-normal budget). A reading without a budget says "not estimated", never ±0.
#pragma once

#include <string>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

// One reading's summary for its line: "BRDF ±2.1 % (k=2; 1.4–3.8 % over bands)", the median of
// U / |f| over the bands where f ≠ 0 and its range; "± not estimated" without a budget; "" for
// readings other than samples.
std::string UncertaintySummary(const v1::Reading& reading, double k);

// Band `band` of a budget for a spectrum's line: "brdf 0.123457 ± 0.00251 sr⁻¹ (k=2)"; "" when
// the band is outside the budget.
std::string UncertaintyBand(const v1::ReadingUncertainty& u, int band, double k);

}  // namespace brdf::ctl
