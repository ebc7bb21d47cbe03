// fill/uncertain_chain: a session's fill chain answering each direction with its uncertainty —
// at a reading's pose the measurement part is that reading's budget, NaN where a blended reading
// has none, model cells far from every reading are not estimated; and the sidecar's
// "uncertainty" object.
#include "core/export/fill/uncertain_chain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "core/export/fill/model_uncertainty.h"
#include "core/export/fill/session_interpolant.h"
#include "core/uncertainty/interpolated.h"
#include "core/uncertainty/loaded_budget.h"
#include "export_test_util.h"

namespace brdf::exports {
namespace {

CallContext LongContext() {
  return CallContext::WithTimeout(std::chrono::hours(1));
}

// A budget of 1 % shared (the session's white standard) and 2 % independent of `values`.
uncertainty::ReadingBudget OnePlusTwoPercent(const std::vector<double>& values) {
  uncertainty::ReadingBudget b;
  uncertainty::Component white{"white_standard", {uncertainty::Sharing::kWhiteStandard, 1}, {}};
  uncertainty::Component signal{"sample_signal", {uncertainty::Sharing::kIndependent, 0}, {}};
  for (double f : values) {
    white.contribution.push_back(0.01 * f);
    signal.contribution.push_back(0.02 * f);
    b.combined.push_back(std::hypot(0.01 * f, 0.02 * f));
    b.independent.push_back(0.02 * f);
  }
  b.components = {white, signal};
  return b;
}

// Each sample gets that budget, in the form a loaded session keeps it (one maker: one list).
void AddBudgets(DerivedSamples& derived) {
  uncertainty::BlendBudgetMaker maker;
  for (DerivedSample& s : derived.samples) {
    s.budget = std::make_shared<const uncertainty::LoadedBudget>(
        uncertainty::LoadBudget(OnePlusTwoPercent(s.values), maker));
  }
}

// The paint-like session's octant interpolant without a fill chain, over its first `keep`
// samples (0: all), each with a budget when `budgets`.
std::optional<SessionInterpolant> PaintOctant(bool budgets, std::size_t keep = 0) {
  std::optional<testing::PaintGridSamples> paint = testing::PaintLikeGridSamples();
  if (!paint) return std::nullopt;
  if (budgets) AddBudgets(paint->derived);
  if (keep > 0) paint->derived.samples.resize(keep);
  Result<SessionInterpolant> in = BuildSessionInterpolant(
      std::move(paint->derived), interp::Method::kOctant, {}, FillPolicy::kNone, LongContext());
  EXPECT_TRUE(in.ok()) << in.status().ToString();
  if (!in.ok()) return std::nullopt;
  return std::move(*in);
}

struct Row {
  interp::InterpStatus status;
  std::vector<double> values;
  std::span<const double> plane(UncertainPlane p) const {
    const std::size_t bands = values.size() / kUncertainPlanes;
    return std::span<const double>(values).subspan(static_cast<std::size_t>(p) * bands, bands);
  }
};

Row Ask(const UncertainChain& chain, const IsoDirection& at, std::size_t bands) {
  Row r{interp::InterpStatus::kOk, std::vector<double>(kUncertainPlanes * bands, 0.0)};
  r.status = chain.chain->Source()(at, r.values);
  return r;
}

// The first sample from the middle of the set on whose pose the chain has a value (the octant
// method has none at the grid's edges), and that answer.
std::pair<std::size_t, Row> AnsweredSample(const UncertainChain& chain,
                                           const DerivedSamples& derived) {
  const std::size_t n = derived.samples.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (n / 2 + k) % n;
    Row row = Ask(chain, derived.samples[i].iso, derived.grid.count);
    if (row.status == interp::InterpStatus::kOk) return {i, std::move(row)};
  }
  ADD_FAILURE() << "no sample's pose has a value";
  return {0, Row{interp::InterpStatus::kOutsideHull, {}}};
}

TEST(UncertainChain, AtAReadingsPoseTheMeasurementPartIsItsBudget) {
  std::optional<testing::PaintGridSamples> paint = testing::PaintLikeGridSamples();
  ASSERT_TRUE(paint.has_value());
  AddBudgets(paint->derived);
  Result<SessionInterpolant> in = BuildSessionInterpolant(paint->derived, interp::Method::kOctant,
                                                          {}, FillPolicy::kNone, LongContext());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  const UncertainChain chain = MakeUncertainChain(*in);
  const auto [index, row] = AnsweredSample(chain, paint->derived);
  ASSERT_EQ(row.status, interp::InterpStatus::kOk);
  const DerivedSample& reading = paint->derived.samples[index];
  const std::vector<double> combined = OnePlusTwoPercent(reading.values).combined;
  const std::size_t bands = reading.values.size();
  for (std::size_t b = 0; b < bands; ++b) {
    EXPECT_NEAR(row.plane(UncertainPlane::kValue)[b], reading.values[b], 1e-12);
    // The blend reads the shared contributions as floats (blend_budget.h): 2⁻²⁴ relative.
    EXPECT_NEAR(row.plane(UncertainPlane::kMeasurement)[b], combined[b], 0x1p-24 * combined[b]);
    EXPECT_NEAR(row.plane(UncertainPlane::kInterpolation)[b], 0.0, 1e-9);
    EXPECT_NEAR(row.plane(UncertainPlane::kCombined)[b], combined[b], 1e-9);
  }
  EXPECT_EQ(chain.coverage.without_budget, 0u);
  EXPECT_GE(chain.chain->Tally().interpolated, 1u);
}

TEST(UncertainChain, ABlendedReadingWithoutBudgetMakesTheMeasurementPartNaN) {
  std::optional<testing::PaintGridSamples> paint = testing::PaintLikeGridSamples();
  ASSERT_TRUE(paint.has_value());
  Result<SessionInterpolant> in = BuildSessionInterpolant(paint->derived, interp::Method::kOctant,
                                                          {}, FillPolicy::kNone, LongContext());
  ASSERT_TRUE(in.ok());
  const UncertainChain chain = MakeUncertainChain(*in);
  const Row row = AnsweredSample(chain, paint->derived).second;
  ASSERT_EQ(row.status, interp::InterpStatus::kOk);
  EXPECT_TRUE(std::isnan(row.plane(UncertainPlane::kMeasurement)[0]));
  EXPECT_TRUE(std::isnan(row.plane(UncertainPlane::kCombined)[0]));
  EXPECT_TRUE(std::isfinite(row.plane(UncertainPlane::kInterpolation)[0]));
  EXPECT_EQ(chain.coverage.without_budget, paint->derived.samples.size());
  ASSERT_EQ(UncertaintyWarnings(chain.coverage).size(), 1u);
  EXPECT_NE(UncertaintyWarnings(chain.coverage)[0].find("have no uncertainty budget"),
            std::string::npos);
}

// Model cells' u is local (fill/model_uncertainty.h): c(d) · ρ from the model's calibration on
// held-out readings by distance (model_uncertainty_test: larger far from the readings, NaN beyond
// the calibration's reach), not the model's residual RMS over all readings. The sidecar says how
// it was fitted and how far it reaches.
TEST(UncertainChain, ModelCellsCarryTheModelsLocalUncertainty) {
  std::optional<testing::PaintGridSamples> paint = testing::PaintLikeGridSamples();
  ASSERT_TRUE(paint.has_value());
  AddBudgets(paint->derived);
  Result<SessionInterpolant> in = BuildSessionInterpolant(paint->derived, interp::Method::kOctant,
                                                          {}, FillPolicy::kChain, LongContext());
  ASSERT_TRUE(in.ok()) << in.status().ToString();
  ASSERT_NE(in->model, nullptr);
  const UncertainChain chain = MakeUncertainChain(*in);
  // Grazing on both sides: beyond every reading, so neither octant nor Delaunay has a value.
  const std::size_t bands = paint->derived.grid.count;
  const IsoDirection grazing{89.5, 89.5, 0.5};
  const Row row = Ask(chain, grazing, bands);
  ASSERT_EQ(row.status, interp::InterpStatus::kOk);
  ASSERT_EQ(chain.chain->Tally().model, 1u) << chain.chain->Tally().Summary();
  ASSERT_EQ(chain.coverage.model_spread.size(), bands);
  ASSERT_TRUE(chain.coverage.model_calibration.has_value());
  const uncertainty::InterpolationCalibration& m = *chain.coverage.model_calibration;
  ASSERT_FALSE(m.scale.empty()) << m.detail;
  EXPECT_GT(m.held_out, 8u);
  EXPECT_GT(m.largest_cell, 0.0);
  const ModelCellUncertainty local(*in->samples,
                                   std::make_shared<const std::vector<std::vector<double>>>(
                                       ModelResiduals(*in->model, *in->samples)),
                                   m);
  std::vector<double> expected(bands);
  local.At(grazing, expected);
  std::size_t differs_from_rms = 0;
  for (std::size_t b = 0; b < bands; ++b) {
    EXPECT_TRUE(std::isfinite(row.plane(UncertainPlane::kValue)[b]));
    EXPECT_TRUE(std::isnan(row.plane(UncertainPlane::kMeasurement)[b]));
    EXPECT_GT(expected[b], 0.0);
    EXPECT_DOUBLE_EQ(row.plane(UncertainPlane::kInterpolation)[b], expected[b]);
    EXPECT_DOUBLE_EQ(row.plane(UncertainPlane::kCombined)[b], expected[b]);
    differs_from_rms += expected[b] != in->model->band_residuals[b].rms;
  }
  EXPECT_EQ(differs_from_rms, bands);
  const std::string j = UncertaintyJson(chain.coverage, Quantity::kBrdf, {});
  EXPECT_NE(j.find("\"model_cells\": {"), std::string::npos) << j;
  EXPECT_NE(j.find("\"not_estimated_beyond_deg\": "), std::string::npos) << j;
}

// The interpolation term is c(λ)·s(λ): the vertices' spread scaled by the stage's calibration
// from held-out readings (the one the Interpolate API computes for the same samples), and the
// sidecar says it is calibrated, on how many held-out readings.
TEST(UncertainChain, TheInterpolationTermIsTheSpreadScaledByTheCalibration) {
  const std::optional<SessionInterpolant> in = PaintOctant(true);
  ASSERT_TRUE(in.has_value());
  const UncertainChain chain = MakeUncertainChain(*in);
  const uncertainty::InterpolationCalibration& c = ChosenCalibration(*in);
  ASSERT_FALSE(c.scale.empty()) << c.detail;
  const std::size_t bands = in->derived->grid.count;
  uncertainty::InterpolatedInputs unscaled;
  unscaled.samples = in->samples.get();
  std::size_t compared = 0;
  for (const DerivedSample& s : in->derived->samples) {
    // Between readings: off each reading's pose by a few degrees.
    const IsoDirection at{s.iso.theta_i + 2.5, s.iso.theta_o + 3.5, s.iso.phi + 7};
    const double q[3] = {at.theta_i, at.theta_o, at.phi};
    const interp::Interpolation answer = in->interpolator->Evaluate(q);
    if (answer.status != interp::InterpStatus::kOk) continue;
    const std::vector<double> spread =
        uncertainty::EstimateInterpolatedUncertainty(answer, unscaled).interpolation;
    const Row row = Ask(chain, at, bands);
    ASSERT_EQ(row.status, interp::InterpStatus::kOk);
    for (std::size_t b = 0; b < bands; ++b) {
      EXPECT_NEAR(row.plane(UncertainPlane::kInterpolation)[b], c.scale[b] * spread[b],
                  1e-12 * spread[b]);
    }
    if (++compared == 10) break;
  }
  EXPECT_EQ(compared, 10u);
  ASSERT_EQ(chain.coverage.calibrations.size(), 1u);
  const std::string j = UncertaintyJson(chain.coverage, Quantity::kBrdf, {});
  EXPECT_NE(j.find("\"interpolation_calibration\": {\"calibrated\": true"), std::string::npos) << j;
  EXPECT_NE(j.find("\"held_out_readings\": " + std::to_string(c.held_out)), std::string::npos);
  EXPECT_TRUE(UncertaintyWarnings(chain.coverage).empty());
}

// Too few readings to hold out: the term is the spread as it is, and the sidecar and the
// report's warnings say why, as the API's not_estimated does.
TEST(UncertainChain, ATermThatCannotBeCalibratedIsTheSpreadAndSaysWhy) {
  const std::optional<SessionInterpolant> in = PaintOctant(false, 10);
  ASSERT_TRUE(in.has_value());
  const UncertainChain chain = MakeUncertainChain(*in);
  ASSERT_EQ(chain.coverage.calibrations.size(), 1u);
  const uncertainty::InterpolationCalibration& c = chain.coverage.calibrations[0].fit;
  EXPECT_TRUE(c.scale.empty());
  EXPECT_NE(c.detail.find("fewer than 8"), std::string::npos) << c.detail;
  const std::string j = UncertaintyJson(chain.coverage, Quantity::kBrdf, {});
  EXPECT_NE(j.find("\"interpolation_calibration\": {\"calibrated\": false"), std::string::npos)
      << j;
  EXPECT_NE(j.find("\"why\": \"" + c.detail + "\""), std::string::npos) << j;
  bool warned = false;
  for (const std::string& w : UncertaintyWarnings(chain.coverage)) {
    warned = warned || w.find("is not calibrated") != std::string::npos;
  }
  EXPECT_TRUE(warned);
}

TEST(UncertainChain, SidecarNamesEachFileItsUnitAndK) {
  UncertaintyCoverage c;
  c.samples = 10;
  c.without_budget = 2;
  const std::string j =
      UncertaintyJson(c, Quantity::kBrdf,
                      {{UncertainPlane::kCombined, "s-grid-brdf.u.npy"},
                       {UncertainPlane::kMeasurement, "s-grid-brdf.u_measurement.npy"}});
  EXPECT_NE(j.find("\"k\": 1"), std::string::npos);
  EXPECT_NE(j.find("\"u\": {\"file\": \"s-grid-brdf.u.npy\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"u_measurement\": {\"file\": \"s-grid-brdf.u_measurement.npy\""),
            std::string::npos);
  EXPECT_NE(j.find("\"samples_without_budget\": 2"), std::string::npos);
  EXPECT_NE(j.find(QuantityUnit(Quantity::kBrdf)), std::string::npos);
}

}  // namespace
}  // namespace brdf::exports
