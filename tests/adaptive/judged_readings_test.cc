// The judged readings' measurement part: a reading blended more than once (the octant method's
// mirror images in φ keep its index) is one reading, its weights summed before its noise is
// squared, as the daemon's blend counts it (core/uncertainty/blend.h).
#include "core/adaptive/judged_readings.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "core/adaptive/interpolated_model.h"
#include "core/geometry.h"
#include "core/interp/octant/octant.h"

namespace brdf::adaptive {
namespace {

TEST(JudgedReadingsTest, MirrorCopiesOfOneReadingCountAsOneInTheMeasurementPart) {
  // Readings on a lattice in (θi, θo) at three φ, each with its own BRDF and relative u; queries
  // near φ = 0, where the octant method's winners on the φ < 0 side are mirror images of the
  // readings on the other.
  std::vector<ReadingSoFar> readings;
  for (double ti : {10.0, 30.0, 50.0}) {
    for (double to : {10.0, 30.0, 50.0}) {
      for (double phi : {15.0, 90.0, 170.0}) {
        const double k = static_cast<double>(readings.size());
        readings.push_back({{}, CanonicalDirections({ti, to, phi}), 1 + 0.1 * k, 0.02 + 0.001 * k});
      }
    }
  }
  const JudgedReadings judged(readings, Judge::kOctant);
  ASSERT_EQ(judged.usable(), readings.size());

  // The same samples and index, to know each answer's vertices and weights.
  auto set = std::make_shared<interp::SampleSet>(3, 1);
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const IsoDirection iso = ToIsotropic(readings[i].directions);
    const double coords[3] = {iso.theta_i, iso.theta_o, iso.phi};
    const double value[1] = {readings[i].brdf};
    ASSERT_TRUE(set->Add(static_cast<std::int64_t>(i), coords, value).ok());
  }
  auto index = interp::OctantInterpolator::Create(set, JudgeOptions(),
                                                  interp::OctantInterpolator::Search::kTree);
  ASSERT_TRUE(index.ok()) << index.status().ToString();

  int with_copies = 0;
  for (double ti : {15.0, 20.0, 25.0, 35.0, 40.0, 45.0}) {
    for (double to : {15.0, 20.0, 25.0, 35.0, 40.0, 45.0}) {
      for (double phi : {1.0, 4.0, 7.0, 11.0}) {
        const std::array<double, 3> point = {ti, to, phi};
        const interp::Interpolation answer = (*index)->Evaluate(point);
        const std::optional<JudgedAnswer> got = judged.Answer(point);
        ASSERT_EQ(got.has_value(), answer.status == interp::InterpStatus::kOk);
        if (!got.has_value()) continue;
        std::map<std::size_t, double> weight;  // per reading, its copies' weights summed
        double separate2 = 0;                  // each copy counted as a reading of its own
        for (const interp::Vertex& v : answer.vertices) {
          weight[v.index] += v.weight;
          const double u =
              v.weight * readings[v.index].relative_uncertainty * readings[v.index].brdf;
          separate2 += u * u;
        }
        double merged2 = 0;
        for (const auto& [i, w] : weight) {
          const double u = w * readings[i].relative_uncertainty * readings[i].brdf;
          merged2 += u * u;
        }
        EXPECT_NEAR(got->u_measurement, std::sqrt(merged2), 1e-12 * std::sqrt(merged2))
            << ti << " " << to << " " << phi;
        if (weight.size() < answer.vertices.size()) {
          ++with_copies;
          // Copies with weights of one sign add linearly: more than in quadrature.
          EXPECT_GT(got->u_measurement, std::sqrt(separate2));
        }
      }
    }
  }
  EXPECT_GT(with_copies, 0) << "no answer blended a reading twice: the test shows nothing";
}

}  // namespace
}  // namespace brdf::adaptive
