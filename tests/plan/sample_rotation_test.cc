// Expansion of sample-rotation plans: the paper's grid, serpentine β, reference blocks, motorized
// axes, conventions, determinism.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "core/geometry.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/plan_settings.h"
#include "core/plan/timing.h"
#include "plan_test_util.h"

namespace brdf::plan {
namespace {

using testing::Expand;
using ::testing::HasSubstr;
using testing::OfKind;
using testing::PlanFromJson;
using testing::Prompts;

v1::Plan DefaultRotation() {
  v1::Plan plan;
  plan.set_name("paper grid");
  plan.mutable_sample_rotation();  // every field at its default
  return plan;
}

bool SameRow(const Pose& a, const Pose& b) {
  return a.alpha == b.alpha && a.delta == b.delta && a.gamma == b.gamma;
}

TEST(SampleRotationTest, DefaultTemplateGivesThePapersGrid) {
  const std::vector<Step> steps = Expand(DefaultRotation());
  const std::vector<Step> samples = OfKind(steps, v1::STEP_KIND_SAMPLE);
  EXPECT_EQ(samples.size(), 2320u);  // the paper's 2,320 poses

  std::vector<IsoDirection> iso;
  std::set<double> deltas;
  for (const Step& s : samples) {
    iso.push_back(ToIsotropic(*s.target));
    deltas.insert(s.pose.delta);
  }
  EXPECT_EQ(CountDistinctIsoPoints(iso), 2153u);  // geometry.md
  EXPECT_EQ(deltas.size(), 14u);                  // 0 … 146.25 every 11.25
  EXPECT_EQ(*deltas.rbegin(), 146.25);

  // Default reference policy: one reference per detector position, each between a mount-white
  // and a mount-sample prompt; one relocation prompt per detector position.
  EXPECT_EQ(OfKind(steps, v1::STEP_KIND_REFERENCE).size(), deltas.size());
  EXPECT_EQ(Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), deltas.size());
  EXPECT_EQ(Prompts(steps, v1::PROMPT_KIND_MOUNT_WHITE).size(), deltas.size());
  EXPECT_EQ(Prompts(steps, v1::PROMPT_KIND_MOUNT_SAMPLE).size(), deltas.size());
  EXPECT_TRUE(OfKind(steps, v1::STEP_KIND_DARK).empty());
  EXPECT_TRUE(Prompts(steps, v1::PROMPT_KIND_SET_GAMMA_DIAL).empty());
}

TEST(SampleRotationTest, ExamplePaperGridFileMatchesTheDefaults) {
  const std::vector<Step> from_defaults = Expand(DefaultRotation());
  std::FILE* f = std::fopen(BRDF_EXAMPLES_DIR "/paper-grid.json", "rb");
  ASSERT_NE(f, nullptr);
  std::string text;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  std::fclose(f);
  const std::vector<Step> from_file = Expand(PlanFromJson(text));
  ASSERT_EQ(from_file.size(), from_defaults.size());
  for (std::size_t i = 0; i < from_file.size(); ++i) {
    EXPECT_EQ(from_file[i].pose, from_defaults[i].pose) << i;
    EXPECT_EQ(from_file[i].kind, from_defaults[i].kind) << i;
  }
}

TEST(SampleRotationTest, StepsAreIndexedAndEverySampleFollowsAMoveToItsPose) {
  const std::vector<Step> steps = Expand(DefaultRotation());
  for (std::size_t i = 0; i < steps.size(); ++i) {
    ASSERT_EQ(steps[i].index, static_cast<int>(i));
    if (steps[i].kind != v1::STEP_KIND_SAMPLE) continue;
    ASSERT_GT(i, 0u);
    EXPECT_EQ(steps[i - 1].kind, v1::STEP_KIND_MOVE) << i;
    EXPECT_EQ(steps[i - 1].pose, steps[i].pose) << i;
    ASSERT_TRUE(steps[i].target.has_value());
    EXPECT_EQ(*steps[i].target, PoseToDirections(steps[i].pose));
    EXPECT_LE(steps[i].target->theta_i, 90);
    EXPECT_LE(steps[i].target->theta_o, 90);
  }
}

TEST(SampleRotationTest, BetaIsSerpentine) {
  const std::vector<Step> samples = OfKind(Expand(DefaultRotation()), v1::STEP_KIND_SAMPLE);
  // Split into rows of constant (δ, α, γ) and check each row's direction.
  std::vector<int> directions;  // +1 ascending, −1 descending per row (rows of ≥ 2 poses)
  std::size_t row_start = 0;
  int rows = 0;
  std::set<std::tuple<double, double, double>> seen_rows;
  for (std::size_t i = 1; i <= samples.size(); ++i) {
    if (i < samples.size() && SameRow(samples[i].pose, samples[i - 1].pose)) continue;
    const Pose& head = samples[row_start].pose;
    // A row is visited once: the stage finishes it before moving on.
    EXPECT_TRUE(seen_rows.insert({head.delta, head.alpha, head.gamma}).second);
    int dir = 0;
    for (std::size_t k = row_start + 1; k < i; ++k) {
      const int d = samples[k].pose.beta > samples[k - 1].pose.beta ? 1 : -1;
      if (dir == 0) dir = d;
      EXPECT_EQ(d, dir) << "β not monotone within the row starting at sample " << row_start;
    }
    if (i - row_start >= 2) {
      // Rows alternate: even rows ascend, odd rows descend.
      EXPECT_EQ(dir, rows % 2 == 0 ? 1 : -1) << "row " << rows;
      directions.push_back(dir);
    }
    ++rows;
    row_start = i;
  }
  EXPECT_EQ(rows, 14 * 8);
  ASSERT_GE(directions.size(), 2u);
}

TEST(SampleRotationTest, FirstBlockIsRelocateReferenceThenSamples) {
  const std::vector<Step> steps = Expand(DefaultRotation());
  ASSERT_GE(steps.size(), 7u);
  EXPECT_EQ(steps[0].prompt, v1::PROMPT_KIND_RELOCATE_DETECTOR);
  EXPECT_EQ(steps[0].pose.delta, 0);
  EXPECT_THAT(steps[0].prompt_text, HasSubstr("δ = 0°"));
  EXPECT_EQ(steps[1].prompt, v1::PROMPT_KIND_MOUNT_WHITE);
  EXPECT_EQ(steps[2].kind, v1::STEP_KIND_MOVE);
  EXPECT_EQ(steps[2].pose, (Pose{0, 0, 0, 0}));  // the default reference pose at δ = 0
  EXPECT_EQ(steps[3].kind, v1::STEP_KIND_REFERENCE);
  EXPECT_EQ(steps[3].pose, steps[2].pose);
  ASSERT_TRUE(steps[3].target.has_value());
  EXPECT_NEAR(steps[3].target->theta_i, 0, 1e-9);  // θi,ref
  EXPECT_EQ(steps[4].prompt, v1::PROMPT_KIND_MOUNT_SAMPLE);
  EXPECT_EQ(steps[5].kind, v1::STEP_KIND_MOVE);
  EXPECT_EQ(steps[6].kind, v1::STEP_KIND_SAMPLE);
  for (const Step& s : steps) {
    if (s.kind == v1::STEP_KIND_PROMPT) {
      EXPECT_FALSE(s.prompt_text.empty());
      EXPECT_FALSE(s.expected_action.empty());
    } else {
      EXPECT_EQ(s.prompt, v1::PROMPT_KIND_UNSPECIFIED);
    }
  }
}

TEST(SampleRotationTest, AutomaticReferencePoseKeepsTheDetectorInFrontOfTheWhite) {
  const std::vector<Step> refs = OfKind(Expand(DefaultRotation()), v1::STEP_KIND_REFERENCE);
  ASSERT_FALSE(refs.empty());
  for (const Step& r : refs) {
    ASSERT_TRUE(r.target.has_value());
    EXPECT_LE(r.target->theta_o, kAutoReferenceMaxThetaODeg + 1e-9) << r.label;
    EXPECT_LE(r.target->theta_i, kReferenceThetaMaxDeg) << r.label;
    if (r.pose.delta <= kAutoReferenceMaxThetaODeg) {
      EXPECT_EQ(r.pose.beta, 0) << r.label;  // geometry.md's default: lamp at normal incidence
    }
  }
}

TEST(SampleRotationTest, DarkReadingFollowsEachReference) {
  v1::Plan plan = DefaultRotation();
  plan.mutable_dark()->set_with_each_reference(true);
  const std::vector<Step> steps = Expand(plan);
  int refs = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i].kind != v1::STEP_KIND_REFERENCE) continue;
    ++refs;
    ASSERT_LT(i + 3, steps.size());
    EXPECT_EQ(steps[i + 1].prompt, v1::PROMPT_KIND_CLOSE_SHUTTER);
    EXPECT_EQ(steps[i + 2].kind, v1::STEP_KIND_DARK);
    EXPECT_EQ(steps[i + 2].pose, steps[i].pose);
    EXPECT_EQ(steps[i + 3].prompt, v1::PROMPT_KIND_MOUNT_SAMPLE);
    EXPECT_THAT(steps[i + 3].prompt_text, HasSubstr("shutter"));
  }
  EXPECT_EQ(static_cast<std::size_t>(refs), OfKind(steps, v1::STEP_KIND_DARK).size());
}

TEST(SampleRotationTest, ReferenceEveryNReadings) {
  v1::Plan plan = DefaultRotation();
  plan.mutable_reference()->set_every_n_readings(100);
  plan.mutable_reference()->set_per_detector_position(false);
  const std::vector<Step> steps = Expand(plan);
  int since = -1;  // no reference yet
  int refs = 0;
  for (const Step& s : steps) {
    if (s.kind == v1::STEP_KIND_REFERENCE) {
      EXPECT_TRUE(since == -1 || since == 100) << "reference after " << since << " samples";
      since = 0;
      ++refs;
    } else if (s.kind == v1::STEP_KIND_SAMPLE) {
      ASSERT_GE(since, 0) << "sample before any reference";
      ++since;
      EXPECT_LE(since, 100);
    }
  }
  EXPECT_EQ(refs, (2320 + 99) / 100);
  // Without per-detector references the detector relocations do not trigger any.
  EXPECT_EQ(Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), 14u);
}

TEST(SampleRotationTest, ReferenceEveryMinutesFollowsTheTimingEstimate) {
  v1::Plan plan = DefaultRotation();
  plan.mutable_reference()->set_per_detector_position(false);
  plan.mutable_reference()->set_every_minutes(20);
  const RigDescription rig;
  const std::vector<Step> steps = Expand(plan, rig);
  const std::vector<StepTime> times = EstimateSteps(steps, rig, ResolveSettings(plan).measurement);
  double clock = 0;
  double last_ref = -1;
  int refs = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    // A reference block starts with MOUNT_WHITE: when it comes, 20 min must have passed (or it
    // is the first); when a sample is measured without one, less than 20 min have passed.
    if (steps[i].prompt == v1::PROMPT_KIND_MOUNT_WHITE && last_ref >= 0) {
      EXPECT_GE(clock - last_ref, 20 * 60) << i;
    }
    if (steps[i].kind == v1::STEP_KIND_MOVE && i + 1 < steps.size() &&
        steps[i + 1].kind == v1::STEP_KIND_SAMPLE && last_ref >= 0 &&
        steps[i - 1].kind != v1::STEP_KIND_PROMPT) {
      EXPECT_LT(clock - last_ref, 20 * 60) << i;
    }
    clock += times[i].estimate_s;
    if (steps[i].kind == v1::STEP_KIND_REFERENCE) {
      last_ref = clock;
      ++refs;
    }
  }
  EXPECT_GT(refs, 2);
}

TEST(SampleRotationTest, MotorizedDetectorArmMovesInsteadOfPrompting) {
  RigDescription rig;
  rig.has_detector_arm = true;
  const std::vector<Step> steps = Expand(DefaultRotation(), rig);
  EXPECT_TRUE(Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).empty());
  // The first step moves the arm to δ = 0; later δ changes are moves too.
  ASSERT_FALSE(steps.empty());
  EXPECT_EQ(steps[0].kind, v1::STEP_KIND_MOVE);
  int delta_moves = 0;
  double delta = -1;
  for (const Step& s : steps) {
    if (s.kind == v1::STEP_KIND_MOVE && s.pose.delta != delta) {
      ++delta_moves;
      delta = s.pose.delta;
    }
  }
  EXPECT_EQ(delta_moves, 14);
  EXPECT_EQ(OfKind(steps, v1::STEP_KIND_SAMPLE).size(), 2320u);
}

TEST(SampleRotationTest, GammaOnAManualDialIsOutermostWithPrompts) {
  v1::Plan plan = DefaultRotation();
  plan.set_anisotropic(true);
  plan.mutable_sample_rotation()->add_gamma(0);
  plan.mutable_sample_rotation()->add_gamma(90);
  const std::vector<Step> steps = Expand(plan);
  const std::vector<Step> dials = Prompts(steps, v1::PROMPT_KIND_SET_GAMMA_DIAL);
  ASSERT_EQ(dials.size(), 2u);
  EXPECT_EQ(dials[0].pose.gamma, 0);
  EXPECT_EQ(dials[1].pose.gamma, 90);
  EXPECT_THAT(dials[1].prompt_text, HasSubstr("γ = 90°"));
  EXPECT_EQ(OfKind(steps, v1::STEP_KIND_SAMPLE).size(), 2 * 2320u);
  EXPECT_EQ(Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), 2 * 14u);
}

TEST(SampleRotationTest, GammaOnAMotorizedAxisKeepsDeltaOutermost) {
  v1::Plan plan = DefaultRotation();
  plan.set_anisotropic(true);
  plan.mutable_sample_rotation()->add_gamma(0);
  plan.mutable_sample_rotation()->add_gamma(90);
  RigDescription rig;
  rig.has_gamma_axis = true;
  const std::vector<Step> steps = Expand(plan, rig);
  EXPECT_TRUE(Prompts(steps, v1::PROMPT_KIND_SET_GAMMA_DIAL).empty());
  EXPECT_EQ(Prompts(steps, v1::PROMPT_KIND_RELOCATE_DETECTOR).size(), 14u);
  double last_delta = -1;
  std::set<double> gammas;
  for (const Step& s : OfKind(steps, v1::STEP_KIND_SAMPLE)) {
    EXPECT_GE(s.pose.delta, last_delta);  // δ never goes back
    last_delta = s.pose.delta;
    gammas.insert(s.pose.gamma);
  }
  EXPECT_EQ(gammas, (std::set<double>{0, 90}));
}

TEST(SampleRotationTest, StepsCarryStageReadingsThroughTheConvention) {
  RigDescription rig;
  rig.convention.alpha.zero_deg = 5;  // the α stage reads 5° at the model's α = 0
  rig.alpha = {0, 95, 10};
  const std::vector<Step> plain = OfKind(Expand(DefaultRotation()), v1::STEP_KIND_SAMPLE);
  const std::vector<Step> shifted = OfKind(Expand(DefaultRotation(), rig), v1::STEP_KIND_SAMPLE);
  ASSERT_EQ(plain.size(), shifted.size());
  for (std::size_t i = 0; i < plain.size(); ++i) {
    EXPECT_DOUBLE_EQ(shifted[i].pose.alpha, plain[i].pose.alpha + 5);
    EXPECT_EQ(shifted[i].target, plain[i].target);  // same directions on the sample
  }
}

TEST(SampleRotationTest, ExpansionIsDeterministic) {
  v1::Plan plan = DefaultRotation();
  plan.mutable_reference()->set_every_minutes(15);
  plan.mutable_dark()->set_with_each_reference(true);
  const std::vector<Step> a = Expand(plan);
  const std::vector<Step> b = Expand(plan);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].kind, b[i].kind);
    EXPECT_EQ(a[i].pose, b[i].pose);
    EXPECT_EQ(a[i].prompt, b[i].prompt);
    EXPECT_EQ(a[i].prompt_text, b[i].prompt_text);
    EXPECT_EQ(a[i].label, b[i].label);
    EXPECT_EQ(a[i].target, b[i].target);
  }
}

TEST(SampleRotationTest, SummaryCountsAndDurations) {
  const RigDescription rig;
  const PlanAnalysis a = AnalyzePlan(DefaultRotation(), rig);
  ASSERT_TRUE(a.valid()) << FormatProblems(a.problems);
  EXPECT_EQ(a.summary.step_count, static_cast<int>(a.steps.size()));
  EXPECT_EQ(a.summary.sample_readings, 2320);
  EXPECT_EQ(a.summary.reference_readings, 14);
  EXPECT_EQ(a.summary.operator_interventions, 14 * 3);
  // Every reading costs at least the transfer and the shortest integration, and the estimate
  // adds overheads and the operator's time on top of the lower bound.
  const int readings = a.summary.sample_readings + a.summary.reference_readings;
  EXPECT_GE(a.summary.physical_lower_bound_s,
            readings * (rig.meter_transfer_s + rig.min_integration_s) - 1e-6);
  EXPECT_GE(a.summary.estimated_duration_s,
            a.summary.physical_lower_bound_s + 42 * rig.operator_action_s);
}

}  // namespace
}  // namespace brdf::plan
