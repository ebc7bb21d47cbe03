// A round's poses expanded after the steps stored before it (plan::ExpandPosesFrom, StartAfter):
// the rig's state carries over, so a round at the detector position the rig is at needs no
// relocation and no reference, and one at another position gets both, as the plan's policies
// say; steps are numbered after the stored ones.
#include <gtest/gtest.h>

#include <vector>

#include "core/plan/expand_steps.h"
#include "core/plan/problem.h"

namespace brdf::plan {
namespace {

// Two poses at δ = 11.25° and a reference per detector position, on a manual detector.
v1::Plan StoredPlan() {
  v1::Plan plan;
  plan.mutable_reference()->set_per_detector_position(true);
  v1::PoseList* list = plan.mutable_pose_list();
  for (double beta : {10.0, 30.0}) {
    v1::PoseEntry* e = list->add_poses();
    e->set_alpha(20);
    e->set_beta(beta);
    e->set_delta(11.25);
  }
  return plan;
}

int Count(const std::vector<Step>& steps, StepKind kind) {
  int n = 0;
  for (const Step& s : steps) n += s.kind == kind;
  return n;
}

TEST(ExpandPosesFromTest, ContinuesFromTheRigsStateWithThePlansPolicies) {
  const RigDescription rig;  // manual detector, manual dial
  const v1::Plan plan = StoredPlan();
  ProblemSink sink;
  const std::vector<Step> stored = ExpandCheckedPlan(plan, rig, sink);
  ASSERT_TRUE(sink.empty());
  const ExpansionStart start = StartAfter(stored, plan, rig);
  EXPECT_TRUE(start.have_reference);
  EXPECT_FALSE(start.relocated_since_reference);
  EXPECT_EQ(start.samples_since_reference, 2u);
  EXPECT_DOUBLE_EQ(start.model.delta, 11.25);
  EXPECT_DOUBLE_EQ(start.model.beta, 30);
  const int first = static_cast<int>(stored.size());

  // Same detector position: moves and readings only.
  const std::vector<Pose> here = {{30, 0, 0, 11.25}, {40, 20, 0, 11.25}};
  const std::vector<Step> same = ExpandPosesFrom(plan, rig, start, here, first);
  ASSERT_EQ(same.size(), 4u);
  EXPECT_EQ(Count(same, v1::STEP_KIND_PROMPT), 0);
  EXPECT_EQ(Count(same, v1::STEP_KIND_REFERENCE), 0);
  EXPECT_EQ(Count(same, v1::STEP_KIND_SAMPLE), 2);
  for (std::size_t i = 0; i < same.size(); ++i) {
    EXPECT_EQ(same[i].index, first + static_cast<int>(i));
  }

  // Another detector position: the relocation prompt, then the reference block, then the pose.
  const std::vector<Pose> there = {{30, 0, 0, 22.5}};
  const std::vector<Step> other = ExpandPosesFrom(plan, rig, start, there, first);
  ASSERT_FALSE(other.empty());
  EXPECT_EQ(other.front().kind, v1::STEP_KIND_PROMPT);
  EXPECT_EQ(other.front().prompt, v1::PROMPT_KIND_RELOCATE_DETECTOR);
  EXPECT_EQ(Count(other, v1::STEP_KIND_REFERENCE), 1);
  EXPECT_EQ(Count(other, v1::STEP_KIND_SAMPLE), 1);
  EXPECT_EQ(other.back().kind, v1::STEP_KIND_SAMPLE);

  // Without the rig's state (a plan of its own) the same poses would start with both.
  v1::Plan fresh = plan;
  fresh.mutable_pose_list()->clear_poses();
  for (const Pose& p : here) {
    v1::PoseEntry* e = fresh.mutable_pose_list()->add_poses();
    e->set_alpha(p.alpha);
    e->set_beta(p.beta);
    e->set_delta(p.delta);
  }
  const std::vector<Step> alone = ExpandCheckedPlan(fresh, rig, sink);
  EXPECT_GT(Count(alone, v1::STEP_KIND_PROMPT), 0);
  EXPECT_EQ(Count(alone, v1::STEP_KIND_REFERENCE), 1);
}

}  // namespace
}  // namespace brdf::plan
