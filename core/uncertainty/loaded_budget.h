// LoadedBudget: what a loaded session (storage/session_readings.h) keeps of a sample reading's
// stored budget of the BRDF, for the exports: the blend's form (blend_budget.h), which a grid
// cell's measurement part blends and whose independent part the held-out calibration reads, and
// the white standard's contribution in double, which the MERL and RGL uncertainty sidecar
// summarises. Nothing else of the budget is read by an export of the loaded session (the readings
// CSV reads Reading::brdf_u; the BiRD export and brdf-export's fit read the stored budgets page by
// page), so a 401-band reading keeps ~16 kB instead of its whole budget's ~39 kB beside a blend
// form made again per export (docs/uncertainty.md, "One blend"). Pure: no I/O.
#pragma once

#include <vector>

#include "core/uncertainty/blend_budget.h"
#include "core/uncertainty/budget.h"

namespace brdf::uncertainty {

struct LoadedBudget {
  // The blend's form, made by the session's BlendBudgetMaker (one list per loaded session). Not
  // blendable (a stored budget whose parts do not all have the same number of bands): it holds
  // only the independent part and not_estimated (bands 0), and the cells blending it have no
  // measurement part.
  BlendBudget blend;
  bool blendable = false;
  // The white_standard component's signed contribution per band as stored; empty: none.
  std::vector<double> white_standard;
};

// `budget` (of the BRDF) in the form a loaded session keeps, its blend form made by `maker`.
LoadedBudget LoadBudget(const ReadingBudget& budget, BlendBudgetMaker& maker);

}  // namespace brdf::uncertainty
