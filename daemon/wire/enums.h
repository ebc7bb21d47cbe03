// brdfd's enums as the API's (proto/brdf/v1) and back: each mapping once, for every room that
// speaks brdf.v1 (the engine's events, the services, brdf-archive). From the API, a value the
// API does not have is nullopt; the service that reads it names the request's field
// (api/common.h). Unspecified values read as the API documents their default.
#pragma once

#include <optional>
#include <string>

#include "brdf/v1/brdf.pb.h"
#include "brdf/v1/plan.pb.h"
#include "core/interp/interpolator.h"
#include "core/readings/quantity.h"
#include "core/readings/reading.h"
#include "core/session_state.h"
#include "daemon/sessions/pause_mode.h"
#include "storage/records.h"

namespace brdf::daemon {

v1::SessionState ToProtoState(SessionState state);
SessionState FromProtoState(v1::SessionState state);  // UNSPECIFIED (and unknown) → kQueued

v1::ReadingKind ToProtoReadingKind(ReadingKind kind);
std::optional<ReadingKind> FromProtoReadingKind(int kind);  // UNSPECIFIED: nullopt

v1::Quantity ToProtoQuantity(Quantity quantity);
std::optional<Quantity> FromProtoQuantity(int quantity);  // UNSPECIFIED → kBrdf

v1::InterpolationMethod ToProtoMethod(interp::Method method);
std::optional<interp::Method> FromProtoMethod(int method);  // UNSPECIFIED → kOctant

// UNSPECIFIED → kIncidence, kNone.
std::optional<interp::Coordinates> FromProtoCoordinates(int coordinates);
std::optional<interp::Trend> FromProtoTrend(int trend);

v1::InterpolationStatus ToProtoInterpStatus(interp::InterpStatus status);

std::optional<PauseMode> FromProtoPauseMode(int mode);  // UNSPECIFIED → kDeferred

// A step's kind as storage keeps it and as the plan (plan.proto) names it.
storage::StepKind ToStorageKind(v1::StepKind kind);  // UNSPECIFIED → kSample
v1::StepKind ToProtoKind(storage::StepKind kind);

// PROMPT_KIND_RELOCATE_DETECTOR ↔ "relocate_detector" (the word stored with a prompt step).
std::string PromptKindWord(v1::PromptKind kind);
v1::PromptKind ParsePromptKindWord(const std::string& word);  // UNSPECIFIED when unknown

// The plan's method as the word stored with its session: "sample_rotation", "sample_fixed",
// "pose_list" ("" when no method is set).
std::string PlanKindWord(const v1::Plan& plan);

}  // namespace brdf::daemon
