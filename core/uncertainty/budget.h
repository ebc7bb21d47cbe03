// The uncertainty budget of one sample reading, per band, after the GUM (docs/uncertainty.md):
//   f = K · (I − D) / (I0 − D),   K = ρw / π · cos θr / cos θi   (the BRDF; K = 1: reflectance)
// Each component is a signed contribution uⱼ = cⱼ · u(xⱼ) per band, in the quantity's unit,
// either independent of every other reading or shared through a named thing (the reference
// reading, the dark reading, the session's white standard, the session's instrument). Two
// readings sharing a component through the same thing covary by the product of their signed
// contributions; independent parts never covary. What cannot be estimated from the inputs is
// named in not_estimated, never counted as zero silently. Pure: no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/readings/quantity.h"
#include "core/status.h"
#include "core/uncertainty/meter_noise.h"
#include "core/wavelength_grid.h"

namespace brdf::uncertainty {

// What a component is shared through; kIndependent: nothing.
enum class Sharing { kIndependent, kReferenceReading, kDarkReading, kWhiteStandard, kInstrument };
// "independent", "reference_reading", "dark_reading", "white_standard", "instrument".
const char* SharingName(Sharing sharing);

struct SharedThrough {
  Sharing kind = Sharing::kIndependent;
  std::int64_t id = 0;  // the reading's id, or the session's for the white standard and instrument
  friend bool operator==(const SharedThrough&, const SharedThrough&) = default;
};

// One named component: its signed contribution per band.
struct Component {
  std::string name;  // "sample_signal", "reference_signal", ... (docs/uncertainty.md's table)
  SharedThrough shared;
  std::vector<double> contribution;
};

struct ReadingBudget {
  Quantity quantity = Quantity::kBrdf;
  std::vector<double> value;  // the quantity per band, as the budget evaluated it
  std::vector<Component> components;
  std::vector<double> combined;     // sqrt(Σ all contributions²) per band
  std::vector<double> independent;  // sqrt(Σ independent contributions²) per band
  // Components the inputs could not estimate, each "name: why" (left out of combined).
  std::vector<std::string> not_estimated;

  const Component* Find(const std::string& name) const;
};

// One measured spectrum: radiance per band as the meter reported it, and how it was measured.
struct MeasuredSignal {
  std::int64_t reading_id = 0;
  std::vector<double> radiance;
  int integration_ms = 0;  // 0: adaptive
  int averages = 1;
};

// The stage's uncertainty per axis (α, β, γ, δ), degrees, standard uncertainties.
struct StageUncertainty {
  std::array<double, 4> repeatability_deg{};  // drawn anew at each move (resolution included)
  std::array<double, 4> alignment_deg{};      // the same at every move (zeros, sample tilt)
};

// The lamp's relative change δ over the reference interval and the reading's share w of it
// (docs/uncertainty.md, "Lamp drift").
struct LampDrift {
  double change = 0;  // δ
  double share = 0;   // w, ≥ 0
};

// The configured terms.
struct BudgetTerms {
  MeterNoiseModel meter;
  double wavelength_nm = 1.1547005383792515;  // u(Δλ): the PR-650's ±2 nm, rectangular
  double stray_light = 0;                     // u(s), a fraction of the white's signal
  StageUncertainty stage;
};

struct BudgetInputs {
  Quantity quantity = Quantity::kBrdf;  // kBrdf or kReflectance
  std::int64_t session_id = 0;
  WavelengthGrid grid;
  MeasuredSignal sample;
  MeasuredSignal reference;
  std::optional<MeasuredSignal> dark;
  std::vector<double> white_reflectance;    // ρw per band (one value: the same for every band)
  std::vector<double> white_reflectance_u;  // u(ρw) per band (one value: the same)
  double theta_i_deg = 0;                   // the sample reading's incidence
  double theta_r_deg = 0;                   // the reference's incidence
  std::optional<LampDrift> drift;           // nullopt: not estimated
  // ∂f/∂(α, β, γ, δ) per band, per degree, of the quantity (pose_gradient.h); nullopt: pose not
  // estimated; an empty axis: that axis not estimated (named when its pose is uncertain).
  std::optional<std::array<std::vector<double>, 4>> pose_gradient;
  BudgetTerms terms;
};

// The budget, or kInvalidArgument naming what is wrong: a quantity other than BRDF or reflectance,
// an invalid grid, a spectrum, ρw, u(ρw) or gradient whose size is neither the grid's count nor
// (ρw, u(ρw)) 1, a band where I0 − D ≤ 0 (named by wavelength), ρw ≤ 0, a negative or non-finite
// uncertainty, θi or θr outside [0°, 90°), a negative drift share, a bad noise model.
Result<ReadingBudget> EstimateReadingBudget(const BudgetInputs& inputs);

}  // namespace brdf::uncertainty
