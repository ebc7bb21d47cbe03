// The fill chain (core/export/fill/chain.h): each direction takes the first stage's ok answer, the
// counts say which stage answered, batches agree with one-by-one answers, and on the synthetic
// paper-grid session a MERL table and a grid have no empty cell above the horizon.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "core/export/fill/chain.h"
#include "core/export/grid/regular_grid.h"
#include "core/export/grid/text.h"
#include "core/export/merl/writer.h"
#include "core/export/synthetic_session.h"
#include "core/interp/interpolator.h"
#include "export_test_util.h"

namespace brdf::exports {
namespace {

using interp::InterpStatus;

CallContext LongContext() {
  return CallContext::WithTimeout(std::chrono::hours(1));
}

// Answers `value` where θi < limit, outside_hull elsewhere.
SpectrumSource Limited(double limit, double value) {
  return [limit, value](const IsoDirection& at, std::span<double> out) {
    if (!(at.theta_i < limit)) return InterpStatus::kOutsideHull;
    for (double& v : out) v = value;
    return InterpStatus::kOk;
  };
}

TEST(FillChain, FirstOkAnswerWinsAndIsCounted) {
  FillChain chain(FillPolicy::kChain, {{Provenance::kInterpolated, Limited(30, 1)},
                                       {Provenance::kFallback, Limited(60, 2)},
                                       {Provenance::kModel, Limited(80, 3)}});
  const SpectrumSource source = chain.Source();
  std::vector<double> out(2, 0.0);
  const double expect[] = {1, 2, 3};
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(source({10.0 + 30 * k, 5, 90}, out), InterpStatus::kOk);
    EXPECT_EQ(out[0], expect[k]);
  }
  // Nothing answers at θi = 85°: the first stage's status, counted empty.
  EXPECT_EQ(source({85, 5, 90}, out), InterpStatus::kOutsideHull);
  // A batch: the same answers, each later stage asked only for what is left.
  const std::vector<double> dirs = {85, 0, 0, 10, 0, 0, 40, 0, 0, 70, 0, 0};
  std::vector<InterpStatus> st(4);
  std::vector<double> spectra(8);
  source.Spectra(dirs, st, spectra);
  EXPECT_EQ(st[0], InterpStatus::kOutsideHull);
  EXPECT_TRUE(std::isnan(spectra[0]) && std::isnan(spectra[1]));
  EXPECT_EQ(spectra[2], 1);
  EXPECT_EQ(spectra[5], 2);
  EXPECT_EQ(spectra[7], 3);
  const FillTally t = chain.Tally();
  EXPECT_EQ(t.interpolated, 2u);
  EXPECT_EQ(t.fallback, 2u);
  EXPECT_EQ(t.model, 2u);
  EXPECT_EQ(t.empty, 2u);
  EXPECT_DOUBLE_EQ(t.model_fraction(), 0.25);
  EXPECT_NE(t.Json().find("\"model\": 2"), std::string::npos);
  EXPECT_NE(t.Summary().find("25.000 %"), std::string::npos);
}

// A batch source: the same answers as Limited, through the batch path (as an interpolator).
SpectrumSource LimitedBatch(double limit, double value) {
  SpectrumSource one = Limited(limit, value);
  return SpectrumSource(
      [one](const IsoDirection& at, std::span<double> out) { return one(at, out); },
      [one](std::span<const double> dirs, std::span<InterpStatus> st, std::span<double> rows) {
        one.Spectra(dirs, st, rows);
      });
}

// A later stage without a batch path (the model) answers rows where they lie: the same rows,
// statuses and counts as through a batch, NaN left where it has no answer.
TEST(FillChain, AStageWithoutABatchPathAnswersInPlaceAsABatchWould) {
  const std::vector<double> dirs = {85, 0, 0, 10, 0, 0, 40, 0, 0, 70, 0, 0, 75, 3, 9};
  for (bool batched : {false, true}) {
    FillChain chain(FillPolicy::kChain,
                    {{Provenance::kInterpolated, LimitedBatch(30, 1)},
                     {Provenance::kFallback, LimitedBatch(60, 2)},
                     {Provenance::kModel, batched ? LimitedBatch(72, 3) : Limited(72, 3)}});
    EXPECT_EQ(chain.Tally().asked(), 0u);
    std::vector<InterpStatus> st(5);
    std::vector<double> rows(10, -7.0);
    chain.Source().Spectra(dirs, st, rows);
    EXPECT_EQ(st[0], InterpStatus::kOutsideHull) << batched;
    EXPECT_EQ(st[3], InterpStatus::kOk) << batched;
    EXPECT_EQ(st[4], InterpStatus::kOutsideHull) << batched;
    const double want[] = {NAN, NAN, 1, 1, 2, 2, 3, 3, NAN, NAN};
    for (std::size_t k = 0; k < rows.size(); ++k) {
      if (std::isnan(want[k])) {
        EXPECT_TRUE(std::isnan(rows[k])) << "value " << k << (batched ? " batched" : "");
      } else {
        EXPECT_EQ(rows[k], want[k]) << "value " << k << (batched ? " batched" : "");
      }
    }
    const FillTally t = chain.Tally();
    EXPECT_EQ(t.interpolated, 1u);
    EXPECT_EQ(t.fallback, 1u);
    EXPECT_EQ(t.model, 1u);
    EXPECT_EQ(t.empty, 2u);
  }
}

// A batch that writes only the rows it answers (FillChain::Stage allows it: the uncertain
// chain's interpolating stages): the rows no stage answers are NaN all the same, the others the
// stage's that answered, under either policy.
SpectrumSource AnsweredRowsOnly(double limit, double value) {
  SpectrumSource one = Limited(limit, value);
  return SpectrumSource(
      [one](const IsoDirection& at, std::span<double> out) { return one(at, out); },
      [one](std::span<const double> dirs, std::span<InterpStatus> st, std::span<double> rows) {
        const std::size_t width = rows.size() / st.size();
        for (std::size_t i = 0; i < st.size(); ++i) {
          st[i] =
              one({dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]}, rows.subspan(i * width, width));
        }
      });
}

TEST(FillChain, RowsNoStageAnsweredAreNaNWhenAStageLeavesThemAlone) {
  const std::vector<double> dirs = {85, 0, 0, 10, 0, 0, 40, 0, 0, 70, 0, 0};
  for (const FillPolicy policy : {FillPolicy::kChain, FillPolicy::kNone}) {
    FillChain chain(policy, {{Provenance::kInterpolated, AnsweredRowsOnly(30, 1)},
                             {Provenance::kFallback, AnsweredRowsOnly(60, 2)},
                             {Provenance::kModel, Limited(65, 3)}});
    std::vector<InterpStatus> st(4);
    std::vector<double> rows(8, -7.0);
    chain.Source().Spectra(dirs, st, rows);
    const bool chained = policy == FillPolicy::kChain;
    const double want[] = {NAN, NAN, 1, 1, chained ? 2 : NAN, chained ? 2 : NAN, NAN, NAN};
    for (std::size_t k = 0; k < rows.size(); ++k) {
      if (std::isnan(want[k])) {
        EXPECT_TRUE(std::isnan(rows[k])) << "value " << k << " " << FillPolicyName(policy);
      } else {
        EXPECT_EQ(rows[k], want[k]) << "value " << k << " " << FillPolicyName(policy);
      }
    }
    EXPECT_EQ(st[3], InterpStatus::kOutsideHull);
    EXPECT_EQ(chain.Tally().empty, chained ? 2u : 3u);
  }
}

TEST(FillChain, PolicyNoneAsksTheMethodAlone) {
  FillChain chain(FillPolicy::kNone, {{Provenance::kInterpolated, Limited(30, 1)},
                                      {Provenance::kModel, Limited(90, 3)}});
  std::vector<double> out(1, 0.0);
  EXPECT_EQ(chain.Source()({50, 5, 90}, out), InterpStatus::kOutsideHull);
  EXPECT_EQ(chain.Tally().empty, 1u);
  EXPECT_EQ(chain.Tally().model, 0u);
  EXPECT_EQ(ParseFillPolicy("chain").value(), FillPolicy::kChain);
  EXPECT_NE(ParseFillPolicy("holes").status().message().find("'holes'"), std::string::npos);
}

TEST(FillChain, ModelSourceEvaluatesTheFittedBands) {
  fit::CookTorranceFit model;
  model.grid = {400, 100, 2};
  model.band = {{0.3, 0.5, 0.2, 0.04}, {0.6, 0.5, 0.2, 0.04}};
  std::vector<double> out(2, 0.0);
  const IsoDirection at{30, 30, 180};
  ASSERT_EQ(ModelSource(model)(at, out), InterpStatus::kOk);
  EXPECT_DOUBLE_EQ(out[0], fit::CookTorranceBrdf(at, model.band[0]));
  EXPECT_DOUBLE_EQ(out[1], fit::CookTorranceBrdf(at, model.band[1]));
  EXPECT_GT(out[1], out[0]);
}

// The product chain on the synthetic paper-grid session: octant, Delaunay, Cook-Torrance.
TEST(FillChain, PaperGridSessionLeavesNoHoleAboveTheHorizon) {
  const std::optional<testing::PaintGridSamples> samples = testing::PaintLikeGridSamples();
  ASSERT_TRUE(samples.has_value());
  const DerivedSamples& derived = samples->derived;
  const std::shared_ptr<const interp::SampleSet>& set = samples->set;
  interp::Options options;
  options.mirror_phi = true;
  options.reciprocity = true;
  auto octant = interp::MakeInterpolator(interp::Method::kOctant, set, options);
  auto delaunay = interp::MakeInterpolator(interp::Method::kDelaunay, set, options);
  ASSERT_TRUE(octant.ok() && delaunay.ok());
  fit::Observations data(derived.grid);
  for (const DerivedSample& s : derived.samples) ASSERT_TRUE(data.Add(s.iso, s.values).ok());
  Result<fit::CookTorranceFit> model = fit::FitCookTorrance(data, {}, LongContext());
  ASSERT_TRUE(model.ok());

  auto chain_of = [&](FillPolicy p) {
    return std::make_unique<FillChain>(
        p, std::vector<FillChain::Stage>{{Provenance::kInterpolated, InterpolatorSource(**octant)},
                                         {Provenance::kFallback, InterpolatorSource(**delaunay)},
                                         {Provenance::kModel, ModelSource(*model)}});
  };
  const SpectralRgbWeights w = testing::D65Weights(derived.grid);
  auto none = chain_of(FillPolicy::kNone);
  Result<MerlExport> holes =
      BuildMerlTable(none->Source(), derived.grid, w, RunControl{2, {}}, LongContext());
  auto chain = chain_of(FillPolicy::kChain);
  Result<MerlExport> full =
      BuildMerlTable(chain->Source(), derived.grid, w, RunControl{2, {}}, LongContext());
  ASSERT_TRUE(holes.ok() && full.ok());
  EXPECT_GT(holes->report.unfilled_total(), 0u);  // the octant method alone leaves holes
  EXPECT_EQ(none->Tally().empty, holes->report.unfilled_total());
  EXPECT_EQ(full->report.unfilled_total(), 0u);
  const FillTally t = chain->Tally();
  EXPECT_EQ(t.empty, 0u);
  EXPECT_EQ(t.asked(), full->report.filled);
  EXPECT_EQ(t.interpolated, holes->report.filled);  // the method's own answers are kept
  EXPECT_GT(t.fallback + t.model, 0u);
  EXPECT_LT(t.model_fraction(), 0.2);

  Result<RegularGrid> grid = MakeRegularGrid(5, 5, 10, GridPlacement::kNodes);
  ASSERT_TRUE(grid.ok());
  auto grid_chain = chain_of(FillPolicy::kChain);
  MemoryGrid sink;
  Result<GridReport> r = ResampleOnGrid(grid_chain->Source(), *grid, derived.grid,
                                        RunControl{2, {}}, LongContext(), sink);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->nan_cells, 0u);
  EXPECT_EQ(grid_chain->Tally().asked(), grid->cells());

  // The sidecar says how the grid was made: symmetry options, axis scales, the fill and its counts.
  const std::string json = GridDescriptionJson(
      *grid, derived.grid, GridExportInfo{1, "demo", Quantity::kBrdf, "octant", 2320, 0}, *r,
      InterpolantInfo{true, true, {1, 1, 0.5}, grid_chain->Tally().Json()});
  EXPECT_NE(json.find("\"mirror_phi\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"reciprocity\": true"), std::string::npos);
  EXPECT_NE(json.find("\"axis_scale\": [1, 1, 0.5]"), std::string::npos);
  EXPECT_NE(json.find("\"fill\": {\"policy\": \"chain\""), std::string::npos);
  EXPECT_NE(GridDescriptionJson(*grid, derived.grid, {}, *r).find("\"axis_scale\": null"),
            std::string::npos);
}

}  // namespace
}  // namespace brdf::exports
