// Translations the engine needs between core/plan's steps, storage's records and the API's
// messages: one place for the step and prompt vocabularies, so the executor (which works from
// stored steps) and the session manager (which stores expanded ones) agree.
#pragma once

#include <google/protobuf/timestamp.pb.h>

#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "brdf/v1/plan.pb.h"
#include "core/plan/step.h"
#include "storage/records.h"

namespace brdf::daemon {

storage::StepKind ToStorageKind(v1::StepKind kind);
v1::StepKind ToProtoKind(storage::StepKind kind);

// PROMPT_KIND_RELOCATE_DETECTOR ↔ "relocate_detector" (the word stored with a prompt step).
std::string PromptKindWord(v1::PromptKind kind);
v1::PromptKind ParsePromptKindWord(const std::string& word);  // UNSPECIFIED when unknown

// "sample_rotation", "sample_fixed", "pose_list" ("" when no method is set).
std::string PlanKindWord(const v1::Plan& plan);

// An expanded step as storage keeps it, and back (for the timing model).
storage::StepRecord ToStepRecord(const plan::Step& step);
plan::Step ToPlanStep(const storage::StepRecord& record);
std::vector<plan::Step> ToPlanSteps(const std::vector<storage::StepRecord>& records);

// A stored prompt step as the API's Prompt (raised_at left unset).
v1::Prompt ToPrompt(const storage::StepRecord& step);

google::protobuf::Timestamp ToTimestamp(storage::UnixSeconds seconds);
google::protobuf::Timestamp NowTimestamp();

v1::Pose ToProtoPose(const Pose& pose);
v1::Directions ToProtoDirections(const Directions& d);
v1::SessionState ToProtoState(SessionState state);
SessionState FromProtoState(v1::SessionState state);  // UNSPECIFIED → kQueued

}  // namespace brdf::daemon
