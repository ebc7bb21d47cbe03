// The interpolated uncertainty model (core/adaptive/interpolated_model.h) on synthetic fields: a
// flat Lambertian field, where gains are small and spread, and a narrow specular peak, where they
// concentrate; a reading lowers the gain where it is; the same readings give the same map; the
// uncertainty left falls as readings come; empty and degenerate inputs answer, never crash.
#include "core/adaptive/interpolated_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <vector>

#include "core/adaptive/candidates.h"
#include "core/adaptive/judged_readings.h"
#include "core/adaptive/round_chooser.h"
#include "core/adaptive/seed_design.h"
#include "core/geometry.h"

namespace brdf::adaptive {
namespace {

using Field = std::function<double(const IsoDirection&)>;

double Rad(double deg) {
  return deg * std::numbers::pi / 180;
}

// The angle between the normal and the half vector of an isotropic point (degrees).
double HalfAngle(const IsoDirection& d) {
  const double hx = std::sin(Rad(d.theta_i)) + std::sin(Rad(d.theta_o)) * std::cos(Rad(d.phi));
  const double hy = std::sin(Rad(d.theta_o)) * std::sin(Rad(d.phi));
  const double hz = std::cos(Rad(d.theta_i)) + std::cos(Rad(d.theta_o));
  return std::atan2(std::hypot(hx, hy), hz) * 180 / std::numbers::pi;
}

const Field kFlat = [](const IsoDirection&) { return 0.2; };
// A diffuse base under a narrow specular lobe (half width about 5° in the half angle).
const Field kPeak = [](const IsoDirection& d) {
  const double h = HalfAngle(d) / 4.2;
  return 0.1 + 5 * std::exp(-0.5 * h * h);
};

AdaptiveSpec Spec(TargetKind kind = TargetKind::kExpandedUncertainty) {
  AdaptiveSpec spec;
  spec.target = {kind, 0.05};
  spec.region.theta_i_max_deg = 75;
  spec.region.theta_o_max_deg = 75;
  return spec;
}

// A small deterministic "noise" of relative size about `u` (a fixed pattern, not random).
double Wiggle(int i, double u) {
  return 1 + u * std::sin(12.9898 * i + 78.233);
}

// n readings of `field` spread over the region (Halton points in θi, θo, φ), relative u 1 %.
std::vector<ReadingSoFar> Readings(const Field& field, int n, double noise = 0.01) {
  std::vector<ReadingSoFar> out;
  for (int i = 1; i <= n; ++i) {
    const IsoDirection iso{75 * RadicalInverse(i, 2), 75 * RadicalInverse(i, 3),
                           180 * RadicalInverse(i, 5)};
    out.push_back({Pose{}, CanonicalDirections(iso), field(iso) * Wiggle(i, noise), 0.01});
  }
  return out;
}

// Readings of `field` on a lattice that reaches the region's edges: θi, θo every 7.5° from 0° to
// 75°, φ every 20° from 0° to 180° (1,210 readings), with the same small wiggle.
std::vector<ReadingSoFar> Lattice(const Field& field, double noise = 0.01) {
  std::vector<ReadingSoFar> out;
  int i = 0;
  for (double ti = 0; ti <= 75; ti += 7.5) {
    for (double to = 0; to <= 75; to += 7.5) {
      for (double phi = 0; phi <= 180; phi += 20) {
        const IsoDirection iso{ti, to, phi};
        out.push_back({Pose{}, CanonicalDirections(iso), field(iso) * Wiggle(++i, noise), 0.01});
      }
    }
  }
  return out;
}

ReadingSoFar At(const Field& field, const IsoDirection& iso) {
  return {Pose{}, CanonicalDirections(iso), field(iso), 0.01};
}

// Candidate points: a lattice over the region.
std::vector<IsoDirection> Candidates() {
  std::vector<IsoDirection> out;
  for (double ti = 2.5; ti < 75; ti += 5) {
    for (double to = 2.5; to < 75; to += 5) {
      for (double phi = 0; phi <= 180; phi += 15) out.push_back({ti, to, phi});
    }
  }
  return out;
}

std::vector<double> Gains(const UncertaintyMap& map, const std::vector<IsoDirection>& at) {
  std::vector<double> out;
  for (const IsoDirection& c : at) out.push_back(map.PredictedGain(CanonicalDirections(c)));
  return out;
}

// The share of the summed gain held by the best tenth of the candidates.
double TopTenthShare(std::vector<double> gains) {
  std::sort(gains.begin(), gains.end(), std::greater<>());
  double top = 0, all = 0;
  for (std::size_t i = 0; i < gains.size(); ++i) {
    all += gains[i];
    if (i < gains.size() / 10) top += gains[i];
  }
  return all > 0 ? top / all : 0;
}

TEST(AdaptiveInterpolatedModelTest, FlatFieldGainsAreSmallAndSpread) {
  const auto model = MakeInterpolatedModel(Spec());
  const std::vector<ReadingSoFar> flat = Lattice(kFlat);
  const std::vector<ReadingSoFar> peak = Lattice(kPeak);
  const auto flat_map = model->Map(flat);
  const auto peak_map = model->Map(peak);
  const std::vector<IsoDirection> candidates = Candidates();
  const std::vector<double> flat_gains = Gains(*flat_map, candidates);
  const std::vector<double> peak_gains = Gains(*peak_map, candidates);
  const double flat_best = *std::max_element(flat_gains.begin(), flat_gains.end());
  const double peak_best = *std::max_element(peak_gains.begin(), peak_gains.end());
  // Flat: little left and little to gain by one reading; far less than beside a peak.
  EXPECT_LT(flat_map->Remaining(), peak_map->Remaining() / 3);
  EXPECT_LT(flat_best, 0.01 * flat_map->Remaining());
  EXPECT_LT(flat_best, peak_best / 10);
  // Spread: the best tenth of the candidates holds a much smaller share of the gain.
  EXPECT_LT(TopTenthShare(flat_gains), TopTenthShare(peak_gains));
}

TEST(AdaptiveInterpolatedModelTest, GainConcentratesNearANarrowPeak) {
  const auto model = MakeInterpolatedModel(Spec());
  const auto map = model->Map(Readings(kPeak, 400));
  const std::vector<IsoDirection> candidates = Candidates();
  std::vector<double> gains = Gains(*map, candidates);
  std::vector<std::size_t> order(gains.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return gains[a] > gains[b]; });
  // Every one of the ten best candidates lies on the lobe (half angle within 12°: about 2.5
  // half widths); a lobe-sized patch is a small part of the lattice.
  for (int i = 0; i < 10; ++i) {
    EXPECT_LT(HalfAngle(candidates[order[i]]), 12)
        << "candidate " << i << ": (" << candidates[order[i]].theta_i << ", "
        << candidates[order[i]].theta_o << ", " << candidates[order[i]].phi << ")";
  }
  EXPECT_GT(gains[order[0]], 0);
}

TEST(AdaptiveInterpolatedModelTest, AReadingAtACandidateLowersItsGain) {
  const auto model = MakeInterpolatedModel(Spec());
  std::vector<ReadingSoFar> readings = Readings(kPeak, 300);
  const IsoDirection on_lobe{40, 42.5, 165};
  const double before = model->Map(readings)->PredictedGain(CanonicalDirections(on_lobe));
  ASSERT_GT(before, 0);
  readings.push_back(At(kPeak, on_lobe));
  const double after = model->Map(readings)->PredictedGain(CanonicalDirections(on_lobe));
  EXPECT_LT(after, before / 10);
}

TEST(AdaptiveInterpolatedModelTest, AssumeTakesAwayWhatWasPredicted) {
  const auto model = MakeInterpolatedModel(Spec());
  const auto map = model->Map(Readings(kPeak, 300));
  const Directions pick = CanonicalDirections({40, 42.5, 165});
  const double before = map->Remaining();
  const double gain = map->PredictedGain(pick);
  ASSERT_GT(gain, 0);
  map->Assume(pick);
  EXPECT_NEAR(map->Remaining(), before - gain, 1e-12);
  // The same spot again: much less to gain.
  EXPECT_LT(map->PredictedGain(pick), gain / 10);
}

TEST(AdaptiveInterpolatedModelTest, SameReadingsGiveTheSameMap) {
  for (Judge judge : {Judge::kOctant, Judge::kDelaunay}) {
    AdaptiveSpec spec = Spec();
    spec.judge = judge;
    const auto model = MakeInterpolatedModel(spec);
    const std::vector<ReadingSoFar> readings = Readings(kPeak, 250);
    const auto a = model->Map(readings);
    const auto b = MakeInterpolatedModel(spec)->Map(readings);
    EXPECT_EQ(a->Remaining(), b->Remaining());
    const std::vector<IsoDirection> candidates = Candidates();
    EXPECT_EQ(Gains(*a, candidates), Gains(*b, candidates));
    a->Assume(CanonicalDirections({30, 30, 180}));
    b->Assume(CanonicalDirections({30, 30, 180}));
    EXPECT_EQ(Gains(*a, candidates), Gains(*b, candidates));
  }
}

TEST(AdaptiveInterpolatedModelTest, RemainingFallsAsReadingsAreAdded) {
  for (Judge judge : {Judge::kOctant, Judge::kDelaunay}) {
    AdaptiveSpec spec = Spec();
    spec.judge = judge;
    const auto model = MakeInterpolatedModel(spec);
    double last = std::numeric_limits<double>::infinity();
    for (int n : {50, 200, 800, 2000}) {
      const double remaining = model->Map(Readings(kPeak, n))->Remaining();
      EXPECT_LT(remaining, last) << n << " readings, judge " << static_cast<int>(judge);
      last = remaining;
    }
  }
}

TEST(AdaptiveInterpolatedModelTest, TheCalibratedScaleComesFromHeldOutReadings) {
  const JudgedReadings judged(Readings(kPeak, 400), Judge::kOctant);
  EXPECT_EQ(judged.usable(), 400u);
  EXPECT_TRUE(judged.calibrated());
  EXPECT_GE(judged.held_out(), 8u);
  EXPECT_GT(judged.scale(), 0);
  // Too few readings to hold any out and still answer: the spread as it is.
  const JudgedReadings few(Readings(kPeak, 5), Judge::kOctant);
  EXPECT_FALSE(few.calibrated());
  EXPECT_EQ(few.scale(), 1);
}

TEST(AdaptiveInterpolatedModelTest, ExpectedErrorIsTheInterpolationTermAtK1) {
  const std::vector<ReadingSoFar> readings = Readings(kPeak, 400);
  const double expanded = MakeInterpolatedModel(Spec())->Map(readings)->Remaining();
  const double expected =
      MakeInterpolatedModel(Spec(TargetKind::kExpectedError))->Map(readings)->Remaining();
  EXPECT_GT(expected, 0);
  EXPECT_LE(expected, expanded / 2 + 1e-15);
}

TEST(AdaptiveInterpolatedModelTest, NoReadingsMeansEverythingIsUnknown) {
  const auto model = MakeInterpolatedModel(Spec());
  const auto map = model->Map({});
  EXPECT_NEAR(map->Remaining(), 2 * kUnknownRelative, 1e-12);
  const double gain = map->PredictedGain(CanonicalDirections({30, 30, 90}));
  EXPECT_GT(gain, 0);
  EXPECT_TRUE(std::isfinite(gain));
  map->Assume(CanonicalDirections({30, 30, 90}));
  EXPECT_LT(map->Remaining(), 2 * kUnknownRelative);
}

TEST(AdaptiveInterpolatedModelTest, DegenerateReadingsAnswerWithoutCrashing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Judge judge : {Judge::kOctant, Judge::kDelaunay}) {
    AdaptiveSpec spec = Spec();
    spec.judge = judge;
    const auto model = MakeInterpolatedModel(spec);
    // Unusable readings are left out: as if there were none.
    std::vector<ReadingSoFar> bad = {{Pose{}, {nan, 0, 30, 0}, 0.1, 0.01},
                                     {Pose{}, {30, 0, 30, 180}, nan, 0.01},
                                     {Pose{}, {30, 0, 30, 180}, 0.1, -1}};
    EXPECT_NEAR(model->Map(bad)->Remaining(), 2 * kUnknownRelative, 1e-12);
    // One reading, three (too few for a Delaunay hull), readings all at one point, a black
    // sample: finite answers, gains ≥ 0.
    const std::vector<std::vector<ReadingSoFar>> cases = {
        {At(kFlat, {30, 30, 90})},
        Readings(kFlat, 3),
        std::vector<ReadingSoFar>(20, At(kFlat, {30, 30, 90})),
        Readings([](const IsoDirection&) { return 0.0; }, 100)};
    for (const std::vector<ReadingSoFar>& readings : cases) {
      const auto map = model->Map(readings);
      EXPECT_TRUE(std::isfinite(map->Remaining()));
      EXPECT_GE(map->Remaining(), 0);
      for (double g : Gains(*map, Candidates())) {
        ASSERT_TRUE(std::isfinite(g));
        ASSERT_GE(g, 0);
      }
      map->Assume(CanonicalDirections({10, 10, 0}));
      EXPECT_TRUE(std::isfinite(map->Remaining()));
    }
  }
}

TEST(AdaptiveInterpolatedModelTest, ChoosesTheSameRoundTwiceAndGoesToThePeak) {
  AdaptiveSpec spec = Spec();
  spec.delta_deg = {0, 22.5, 45, 67.5, 90};
  const auto model = MakeInterpolatedModel(spec);
  const std::vector<Pose> candidates = CandidatePoses(spec, plan::RigDescription{});
  v1::Plan policies;
  policies.mutable_reference()->set_per_detector_position(true);
  const RoundCost cost(policies, plan::RigDescription{});
  const std::vector<ReadingSoFar> readings = Readings(kPeak, 300);
  const RoundInput input{readings, candidates, Pose{0, 20, 0, 45}, {300, 0, 0}, {1000, 0, 0}};
  const Round a = ChooseRound(input, *model, cost);
  const Round b = ChooseRound(input, *model, cost);
  ASSERT_EQ(a.poses.size(), 24u);
  ASSERT_EQ(a.poses.size(), b.poses.size());
  int on_lobe = 0;
  for (std::size_t i = 0; i < a.poses.size(); ++i) {
    EXPECT_EQ(a.poses[i].pose, b.poses[i].pose);
    EXPECT_EQ(a.poses[i].predicted_gain, b.poses[i].predicted_gain);
    on_lobe += HalfAngle(ToIsotropic(PoseToDirections(a.poses[i].pose))) < 12 ? 1 : 0;
  }
  // The lobe (half angle within 12°) holds few of the candidates (60 of 1,345), yet the round
  // picks there at least five times as often as a pick at random would (10 of 24 when written).
  int lobe_candidates = 0;
  for (const Pose& c : candidates) {
    lobe_candidates += HalfAngle(ToIsotropic(PoseToDirections(c))) < 12 ? 1 : 0;
  }
  ASSERT_GT(lobe_candidates, 0);
  EXPECT_GT(on_lobe * static_cast<int>(candidates.size()),
            5 * lobe_candidates * static_cast<int>(a.poses.size()))
      << on_lobe << " picks on the lobe; " << lobe_candidates << " of " << candidates.size()
      << " candidates";
}

}  // namespace
}  // namespace brdf::adaptive
