// Fuzz target: plans as they arrive from a client or a file (core/plan): ParsePlanJson, then
// AnalyzePlan / ValidatePlan / ExpandPlan against the paper's rig (the default RigDescription)
// and a fully motorized one, plus the JSON scanner that places error messages (json_locator.h).
//
// Promises checked: a valid plan expands into 1..kMaxSteps steps indexed in order, every MOVE
// within the rig's travel and every pose finite, the summary counting them; an invalid plan has
// no steps and every problem has a message; the three entry points agree; a parsed plan survives
// PlanToJson and back unchanged.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/plan/analyze_plan.h"
#include "core/plan/json_locator.h"
#include "core/plan/plan_json.h"
#include "core/plan/plan_settings.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {
namespace {

using namespace brdf::plan;

bool Finite(const Pose& p) {
  return std::isfinite(p.alpha) && std::isfinite(p.beta) && std::isfinite(p.gamma) &&
         std::isfinite(p.delta);
}

void CheckAnalysis(const v1::Plan& plan, const RigDescription& rig) {
  const PlanAnalysis a = AnalyzePlan(plan, rig);
  if (a.valid()) {
    BRDF_FUZZ_CHECK(!a.steps.empty(), "a valid plan without steps");
    BRDF_FUZZ_CHECK(a.steps.size() <= static_cast<std::size_t>(kMaxSteps),
                    "a valid plan beyond the step cap: " + std::to_string(a.steps.size()));
    BRDF_FUZZ_CHECK(a.summary.step_count == static_cast<int>(a.steps.size()),
                    "the summary miscounts the steps");
    int readings = 0;
    for (std::size_t i = 0; i < a.steps.size(); ++i) {
      const Step& s = a.steps[i];
      BRDF_FUZZ_CHECK(s.index == static_cast<int>(i), "step index out of order");
      BRDF_FUZZ_CHECK(Finite(s.pose), "a step with a non-finite pose: " + s.label);
      if (s.is_reading()) ++readings;
      if (s.kind == v1::STEP_KIND_MOVE) {
        BRDF_FUZZ_CHECK(rig.alpha.Contains(s.pose.alpha) && rig.beta.Contains(s.pose.beta),
                        "a move beyond the α/β travel: " + s.label);
        if (rig.has_gamma_axis) {
          BRDF_FUZZ_CHECK(rig.gamma.Contains(s.pose.gamma), "a move beyond γ travel: " + s.label);
        }
        if (rig.has_detector_arm) {
          BRDF_FUZZ_CHECK(rig.delta.Contains(s.pose.delta), "a move beyond δ travel: " + s.label);
        }
      }
      if (s.kind == v1::STEP_KIND_PROMPT) {
        BRDF_FUZZ_CHECK(!s.prompt_text.empty(), "a prompt without a text");
      }
    }
    BRDF_FUZZ_CHECK(
        a.summary.sample_readings + a.summary.reference_readings + a.summary.dark_readings ==
            readings,
        "the summary miscounts the readings");
    BRDF_FUZZ_CHECK(
        std::isfinite(a.summary.estimated_duration_s) && a.summary.estimated_duration_s >= 0,
        "a non-finite or negative duration estimate");
  } else {
    BRDF_FUZZ_CHECK(a.steps.empty(), "an invalid plan with steps");
    for (const Problem& p : a.problems) {
      BRDF_FUZZ_CHECK(!p.message.empty(), "a problem without a message at " + p.field_path);
    }
  }
  // The other entry points redo the whole expansion; comparing them on big plans would cost
  // most of the fuzzer's time for no new paths.
  if (a.steps.size() > 5000) return;
  const std::vector<Problem> problems = ValidatePlan(plan, rig);
  BRDF_FUZZ_CHECK(problems == a.problems, "ValidatePlan and AnalyzePlan disagree");
  const Result<std::vector<Step>> expanded = ExpandPlan(plan, rig);
  BRDF_FUZZ_CHECK(expanded.ok() == a.valid(), "ExpandPlan and AnalyzePlan disagree");
  if (expanded.ok()) {
    BRDF_FUZZ_CHECK(expanded->size() == a.steps.size(), "ExpandPlan gives another step count");
  }
}

}  // namespace

int FuzzPlanJson(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = AsText(data, size);

  const JsonLocator locator(text);
  if (locator.error()) {
    BRDF_FUZZ_CHECK(!locator.error()->message.empty(), "a syntax error without a message");
    BRDF_FUZZ_CHECK(locator.error()->at.line >= 1 && locator.error()->at.column >= 1,
                    "a syntax error before line 1, column 1");
  }

  const Result<v1::Plan> plan = ParsePlanJson(text);
  if (!plan.ok()) {
    BRDF_FUZZ_CHECK(plan.status().code() == StatusCode::kInvalidArgument,
                    "an unparsable plan is not kInvalidArgument: " + plan.status().ToString());
    return 0;
  }

  const Result<std::string> json = PlanToJson(*plan);
  BRDF_FUZZ_CHECK(json.ok(), "a parsed plan does not print: " + json.status().ToString());
  const Result<v1::Plan> again = ParsePlanJson(*json);
  BRDF_FUZZ_CHECK(again.ok(),
                  "a printed plan does not parse: " + again.status().ToString() + "\n" + *json);
  BRDF_FUZZ_CHECK(again->SerializeAsString() == plan->SerializeAsString(),
                  "a plan changed through PlanToJson and back:\n" + *json);

  CheckAnalysis(*plan, RigDescription{});
  RigDescription motorized;
  motorized.has_gamma_axis = true;
  motorized.has_detector_arm = true;
  CheckAnalysis(*plan, motorized);
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzPlanJson)
