// fill/model_uncertainty: the fill chain's model cells' local uncertainty — the distance to the
// readings, their nearest neighbours, u growing with the distance and not estimated beyond the
// calibration's reach, and the calibration from the model refitted without held-out readings.
#include "core/export/fill/model_uncertainty.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "export_test_util.h"

namespace brdf::exports {
namespace {

TEST(ReadingDistance, IsTheIncidenceAndTheOutgoingAngleInQuadrature) {
  EXPECT_NEAR(ReadingDistance({10, 30, 0}, {10, 30, 0}), 0.0, 1e-6);
  EXPECT_NEAR(ReadingDistance({10, 30, 0}, {13, 34, 0}), 5.0, 1e-9);
  // At θo = 0 the azimuth names the same direction.
  EXPECT_NEAR(ReadingDistance({20, 0, 0}, {20, 0, 170}), 0.0, 1e-6);
  // θo = 90° at φ = 0 and φ = 90: a right angle apart.
  EXPECT_NEAR(ReadingDistance({0, 90, 0}, {0, 90, 90}), 90.0, 1e-9);
  // Near the pole a large change of φ is a small change of direction.
  EXPECT_LT(ReadingDistance({0, 5, 0}, {0, 5, 90}), 8.0);
}

// The k smallest (distance, position) pairs over every reading: what Nearest must give.
std::vector<std::pair<double, std::size_t>> BruteForceNearest(const interp::SampleSet& samples,
                                                              const IsoDirection& at,
                                                              std::size_t k) {
  std::vector<std::pair<double, std::size_t>> all;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::span<const double> c = samples.coords(i);
    all.emplace_back(ReadingDistance(at, {c[0], c[1], c[2]}), i);
  }
  std::sort(all.begin(), all.end());
  all.resize(std::min(k, all.size()));
  return all;
}

// One query's k nearest as positions and distances, equal to the brute force's, bit for bit.
void ExpectAsBruteForce(const ReadingNeighbours& neighbours, const interp::SampleSet& samples,
                        const IsoDirection& at, std::size_t k) {
  std::vector<std::size_t> index;
  std::vector<double> distance;
  neighbours.Nearest(at, k, &index, &distance);
  const auto expected = BruteForceNearest(samples, at, k);
  ASSERT_EQ(distance.size(), expected.size());
  for (std::size_t j = 0; j < expected.size(); ++j) {
    EXPECT_EQ(distance[j], expected[j].first) << at.theta_i << " " << at.theta_o << " " << j;
    EXPECT_EQ(index[j], expected[j].second) << at.theta_i << " " << at.theta_o << " " << j;
  }
}

// Every query's k nearest, as above.
void ExpectNearestAsBruteForce(const interp::SampleSet& samples,
                               const std::vector<IsoDirection>& queries, std::size_t k) {
  const ReadingNeighbours neighbours(samples);
  for (const IsoDirection& at : queries) ExpectAsBruteForce(neighbours, samples, at, k);
}

// `n` readings at random (θi, θo) in [0, theta_max) and φ in [0, 180), one band each.
interp::SampleSet ScatteredReadings(unsigned seed, int n, double theta_max) {
  interp::SampleSet samples(3, 1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> theta(0, theta_max), phi(0, 180);
  for (int i = 0; i < n; ++i) {
    const double c[3] = {theta(rng), theta(rng), phi(rng)};
    const double v[1] = {1.0};
    EXPECT_TRUE(samples.Add(i, c, v).ok());
  }
  return samples;
}

TEST(ReadingNeighbours, FindsTheNearestReadingsAsABruteForceSearchDoes) {
  const interp::SampleSet samples = ScatteredReadings(7, 200, 80);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> theta(0, 80), phi(0, 180);
  std::vector<IsoDirection> queries;
  for (int q = 0; q < 50; ++q) queries.push_back({theta(rng), theta(rng), phi(rng)});
  ExpectNearestAsBruteForce(samples, queries, 4);
}

// A rig-like grid of readings: θi 10–60° by 10, θo 0–70° by 5, φ 0–180° by 30 (many readings on
// the same θi and θo, equal distances everywhere), the readings at φ = 90° twice.
interp::SampleSet RigLikeReadings() {
  interp::SampleSet samples(3, 1);
  std::int64_t id = 0;
  for (double ti = 10; ti <= 60; ti += 10) {
    for (double to = 0; to <= 70; to += 5) {
      for (double ph = 0; ph <= 180; ph += 30) {
        const double c[3] = {ti, to, ph};
        const double v[1] = {1.0};
        EXPECT_TRUE(samples.Add(id++, c, v).ok());
        if (ph == 90) {
          EXPECT_TRUE(samples.Add(id++, c, v).ok());
        }
      }
    }
  }
  return samples;
}

TEST(ReadingNeighbours, AgreesWithTheBruteForceOnAGridWithTiesAndQueriesBeyondIt) {
  // A rig-like grid (many readings on the same θi and θo, equal distances everywhere), some
  // readings twice, and queries inside it, between its rows, beyond its edges and at the pole.
  const interp::SampleSet samples = RigLikeReadings();
  std::vector<IsoDirection> queries = {{10, 0, 0},   {35, 32.5, 45}, {0, 0, 0},    {89, 89, 180},
                                       {60, 70, 90}, {25, 80, 10},   {70, 5, 170}, {40, 20, 90}};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> theta(0, 90), phi(0, 180);
  for (int q = 0; q < 200; ++q) queries.push_back({theta(rng), theta(rng), phi(rng)});
  for (const std::size_t k : {std::size_t{1}, std::size_t{4}, std::size_t{9}}) {
    ExpectNearestAsBruteForce(samples, queries, k);
  }
  // More than there are: every reading, in order.
  interp::SampleSet few(3, 1);
  for (int i = 0; i < 3; ++i) {
    const double c[3] = {10.0 * i, 5.0, 0.0};
    const double v[1] = {1.0};
    ASSERT_TRUE(few.Add(i, c, v).ok());
  }
  ExpectNearestAsBruteForce(few, {{50, 50, 50}, {0, 0, 0}}, 4);
}

TEST(ReadingNeighbours, AgreesWithTheBruteForceForQueriesInAGridsOrder) {
  // A grid asks for neighbouring cells in turn, so each query starts from the last one's reach:
  // cells in the export's order (φ fastest, then θo, then θi) beyond and among rig-like readings
  // with ties, two sets asked alternately and k changing, all as the brute force's, bit for bit.
  const interp::SampleSet rig = RigLikeReadings();
  const interp::SampleSet scattered = ScatteredReadings(11, 90, 70);
  std::vector<IsoDirection> cells;
  for (double ti = 5; ti < 90; ti += 10) {
    for (double to = 2.5; to < 90; to += 7.5) {
      for (double ph = 1; ph < 180; ph += 6) cells.push_back({ti, to, ph});
    }
  }
  const ReadingNeighbours on_rig(rig), on_scattered(scattered);
  for (std::size_t n = 0; n < cells.size(); ++n) {
    const bool first = n % 50 < 40;  // the two sets in runs, so each starts warm and cold
    const std::size_t k = n % 200 < 150 ? 4 : 2;
    ExpectAsBruteForce(first ? on_rig : on_scattered, first ? rig : scattered, cells[n], k);
  }
}

// Readings every 20° in θi and θo in the plane, each with a model residual of 0.01 in its one
// band, and a calibration whose c is 1 up to 5° from a reading, 3 beyond, reaching 30°.
struct Fixture {
  interp::SampleSet samples{3, 1};
  std::unique_ptr<ModelCellUncertainty> u;
  Fixture() {
    int id = 0;
    for (double ti = 0; ti <= 60; ti += 20) {
      for (double to = 0; to <= 60; to += 20) {
        const double c[3] = {ti, to, 0};
        const double v[1] = {0.5};
        EXPECT_TRUE(samples.Add(id++, c, v).ok());
      }
    }
    auto residuals =
        std::make_shared<const std::vector<std::vector<double>>>(samples.size(), std::vector{0.01});
    uncertainty::InterpolationCalibration c;
    c.scale = {1.0};
    c.band_groups = 1;
    c.larger = {{5.0, {3.0}}};
    c.largest_cell = 30.0;
    c.beyond = uncertainty::SizeBeyond::kNotEstimated;
    u = std::make_unique<ModelCellUncertainty>(samples, std::move(residuals), std::move(c));
  }
  double At(const IsoDirection& d) const {
    double out[1] = {0};
    u->At(d, out);
    return out[0];
  }
};

TEST(ModelCellUncertainty, ACellFarFromTheReadingsGetsALargerUThanOneNearThem) {
  const Fixture f;
  const double at_reading = f.At({20, 20, 0});
  const double near = f.At({21, 22, 0});      // 2.2° from a reading
  const double far = f.At({30, 30, 0});       // 14° from the nearest
  const double farther = f.At({30, 30, 60});  // out of the plane, ~28° away
  EXPECT_NEAR(at_reading, 0.01, 1e-12);
  EXPECT_NEAR(near, 0.01, 1e-12);
  EXPECT_NEAR(far, 0.03, 1e-12);
  EXPECT_GT(far, near);
  EXPECT_GE(farther, far);
}

TEST(ModelCellUncertainty, ACellBeyondTheCalibrationsReachIsNotEstimated) {
  const Fixture f;
  EXPECT_TRUE(std::isnan(f.At({30, 60, 120})));  // far out of the plane
  EXPECT_TRUE(std::isnan(f.At({89, 89, 90})));
  // An uncalibrated model gives no u anywhere.
  uncertainty::InterpolationCalibration none;
  const ModelCellUncertainty u(
      f.samples,
      std::make_shared<const std::vector<std::vector<double>>>(f.samples.size(), std::vector{0.01}),
      none);
  double out[1] = {0};
  u.At({20, 20, 0}, out);
  EXPECT_TRUE(std::isnan(out[0]));
}

// On the paint-like session: the refitted model predicts every held-out reading, the calibration
// has distance bins whose c never shrinks with the distance, and its reach is a held-out reading's
// distance from the rest.
TEST(CalibrateModel, IsFittedByDistanceOnHeldOutReadings) {
  std::optional<testing::PaintGridSamples> paint = testing::PaintLikeGridSamples();
  ASSERT_TRUE(paint.has_value());
  const interp::SampleSet& samples = *paint->set;
  const uncertainty::InterpolationCalibration c = CalibrateModel(
      samples, paint->derived.grid, CallContext::WithTimeout(std::chrono::minutes(5)));
  ASSERT_FALSE(c.scale.empty()) << c.detail;
  EXPECT_GE(c.held_out, std::min<std::size_t>(samples.size(), uncertainty::kMaxHeldOut) - 8);
  EXPECT_LE(c.held_out, uncertainty::kMaxHeldOut);
  ASSERT_FALSE(c.larger.empty()) << c.detail;
  EXPECT_GT(c.largest_cell, 0.0);
  EXPECT_EQ(c.beyond, uncertainty::SizeBeyond::kNotEstimated);
  for (std::size_t b = 0; b < c.scale.size(); ++b) {
    double previous = c.scale[b];
    for (const uncertainty::SizeBin& bin : c.larger) {
      EXPECT_GE(bin.scale[b], previous);
      previous = bin.scale[b];
    }
  }
}

}  // namespace
}  // namespace brdf::exports
