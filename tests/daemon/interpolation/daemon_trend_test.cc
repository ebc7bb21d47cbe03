// The bivariate trend over gRPC (InterpolationOptions.trend), against a real brdfd recording from
// brdf-sim (noiseless):
//   - brdfd's answers with the trend are core/interp's over the same readings (the BRDF recomputed
//     from StreamReadings' raw spectra), for the three methods, and differ from those without;
//   - the index cache keeps the two apart: none, bivariate, none again gives the first answers
//     bit for bit;
//   - an anisotropic session is refused with INVALID_ARGUMENT naming options.trend and what to
//     do; an unknown trend value names the field.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "core/interp/interpolator.h"
#include "tests/daemon/interpolation/derived_readings.h"
#include "tests/daemon/interpolation/rig_test.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

const std::string kAnisotropicPlan = plans::TwoAnisotropicPoses("anisotropic trend refusal");

v1::InterpolationOptions Trend(v1::InterpolationTrend t, bool symmetries = true) {
  v1::InterpolationOptions o;
  o.set_trend(t);
  o.set_mirror_phi(symmetries);
  o.set_reciprocity(symmetries);
  return o;
}

class DaemonTrendTest : public InterpolationRigTest {};

TEST_F(DaemonTrendTest, AnswersAreCoresAndTheCacheKeepsTrendsApart) {
  std::string id;
  ASSERT_NO_FATAL_FAILURE(Record(plans::InterpolationGrid().Retry(2, 0), &id));
  Result<std::vector<v1::Reading>> all = rig_.Readings(id);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  std::shared_ptr<interp::SampleSet> set = BrdfSampleSet(*all);
  ASSERT_NE(set, nullptr);
  ASSERT_GE(set->size(), 20u);

  const std::vector<IsoDirection> queries = MidpointQueries(*set);

  for (const auto& [method, core_method] :
       {std::pair{v1::INTERPOLATION_METHOD_OCTANT, interp::Method::kOctant},
        std::pair{v1::INTERPOLATION_METHOD_DELAUNAY, interp::Method::kDelaunay},
        std::pair{v1::INTERPOLATION_METHOD_NEAREST, interp::Method::kNearest}}) {
    SCOPED_TRACE(interp::MethodName(core_method));
    std::vector<v1::InterpolationResult> plain, trend, again;
    ASSERT_TRUE(Batch(id, queries, method, v1::QUANTITY_BRDF, &plain,
                      Trend(v1::INTERPOLATION_TREND_UNSPECIFIED))
                    .ok());
    grpc::Status st = Batch(id, queries, method, v1::QUANTITY_BRDF, &trend,
                            Trend(v1::INTERPOLATION_TREND_BIVARIATE));
    ASSERT_TRUE(st.ok()) << st.error_message();
    ASSERT_TRUE(
        Batch(id, queries, method, v1::QUANTITY_BRDF, &again, Trend(v1::INTERPOLATION_TREND_NONE))
            .ok());
    ASSERT_EQ(trend.size(), queries.size());
    ASSERT_EQ(again.size(), plain.size());

    interp::Options options;
    options.mirror_phi = options.reciprocity = true;
    options.trend = interp::Trend::kBivariate;
    auto core = interp::MakeInterpolator(core_method, set, options);
    ASSERT_TRUE(core.ok()) << core.status().ToString();

    int ok = 0, differ = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
      const double p[3] = {queries[i].theta_i, queries[i].theta_o, queries[i].phi};
      const interp::Interpolation want = (*core)->Evaluate(p);
      ASSERT_EQ(trend[i].status() == v1::INTERPOLATION_STATUS_OK,
                want.status == interp::InterpStatus::kOk)
          << trend[i].detail() << " / " << want.detail;
      if (want.status == interp::InterpStatus::kOk) {
        ++ok;
        EXPECT_LT(RelativeGap(trend[i].spectrum(), want.spectrum), 1e-9);
        EXPECT_NE(trend[i].detail().find("bivariate trend"), std::string::npos)
            << trend[i].detail();
        if (plain[i].status() == v1::INTERPOLATION_STATUS_OK) {
          const std::vector<double> p_spectrum(plain[i].spectrum().begin(),
                                               plain[i].spectrum().end());
          if (RelativeGap(trend[i].spectrum(), p_spectrum) > 1e-6) ++differ;
        }
      }
      ASSERT_EQ(again[i].spectrum_size(), plain[i].spectrum_size());
      for (int b = 0; b < again[i].spectrum_size(); ++b) {
        EXPECT_EQ(again[i].spectrum(b), plain[i].spectrum(b));
      }
    }
    EXPECT_GT(ok, 0);
    EXPECT_GT(differ, ok / 2) << differ << " of " << ok;
  }
}

TEST_F(DaemonTrendTest, AnisotropicSessionAndUnknownTrendAreRefusedWithWhatToDo) {
  std::string id;
  ASSERT_NO_FATAL_FAILURE(Record(kAnisotropicPlan, &id));
  const v1::DirectionQuery four = Four(20, 0, 30, 150);
  v1::InterpolationResult result;
  grpc::Status st = Interpolate(id, four, v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE,
                                &result, Trend(v1::INTERPOLATION_TREND_NONE, false));
  ASSERT_TRUE(st.ok()) << st.error_message();
  st = Interpolate(id, four, v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE, &result,
                   Trend(v1::INTERPOLATION_TREND_BIVARIATE, false));
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  for (const char* part : {"options.trend", "isotropic", "anisotropic", "NONE"}) {
    EXPECT_NE(st.error_message().find(part), std::string::npos) << st.error_message();
  }
  st = Interpolate(id, four, v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE, &result,
                   Trend(static_cast<v1::InterpolationTrend>(9), false));
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(st.error_message().find("options.trend"), std::string::npos) << st.error_message();
}

}  // namespace
}  // namespace brdf::testing
