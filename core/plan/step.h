// A step: one thing the executor does — move the stage, ask the operator for a manual action,
// or take a reading. A session is the list of steps its plan expands into (ExpandPlan), stored
// at submission and run in index order; nothing else decides what the rig does next.
#pragma once

#include <optional>
#include <string>

#include "brdf/v1/plan.pb.h"
#include "core/pose.h"

namespace brdf::plan {

using StepKind = v1::StepKind;      // STEP_KIND_MOVE, _PROMPT, _REFERENCE, _DARK, _SAMPLE
using PromptKind = v1::PromptKind;  // PROMPT_KIND_RELOCATE_DETECTOR, _MOUNT_WHITE, ...

struct Step {
  // Position in the plan's step list, 0-based; equals the step's index in the vector.
  int index = 0;
  StepKind kind = v1::STEP_KIND_UNSPECIFIED;
  // The rig's pose during the step, as stage readings (degrees). MOVE: where to go (the
  // executor moves the motorized axes: α, β, plus γ and δ when the rig has those motors).
  // PROMPT/REFERENCE/DARK/SAMPLE: where the rig is (δ: where the detector is or must be put).
  // Sample-fixed steps: the equivalent pose by inverse kinematics (the holder does not move).
  Pose pose;
  // PROMPT steps: what the operator must do; PROMPT_KIND_UNSPECIFIED for other kinds.
  PromptKind prompt = v1::PROMPT_KIND_UNSPECIFIED;
  // PROMPT steps: the full instruction ("Move the detector to δ = 22.5° …, then confirm.").
  std::string prompt_text;
  // PROMPT steps: the state the operator's confirmation asserts ("detector at δ = 22.5°").
  std::string expected_action;
  // Short description for logs and stored readings ("sample δ 22.5° α 10° β -35° γ 0°").
  std::string label;
  // Reading steps (REFERENCE, DARK, SAMPLE): the lamp and detector directions in the sample's
  // frame (for a reference: θi,ref of the BRDF formula). Sample-fixed relocation prompts: the
  // target to set up. Unset for moves and other prompts.
  std::optional<Directions> target;

  bool is_reading() const {
    return kind == v1::STEP_KIND_REFERENCE || kind == v1::STEP_KIND_DARK ||
           kind == v1::STEP_KIND_SAMPLE;
  }
};

}  // namespace brdf::plan
