#include "daemon/wire/enums.h"

#include <cctype>
#include <string_view>

namespace brdf::daemon {

v1::SessionState ToProtoState(SessionState state) {
  switch (state) {
    case SessionState::kQueued:
      return v1::SESSION_STATE_QUEUED;
    case SessionState::kRunning:
      return v1::SESSION_STATE_RUNNING;
    case SessionState::kPausing:
      return v1::SESSION_STATE_PAUSING;
    case SessionState::kPaused:
      return v1::SESSION_STATE_PAUSED;
    case SessionState::kAwaitingOperator:
      return v1::SESSION_STATE_AWAITING_OPERATOR;
    case SessionState::kCompleted:
      return v1::SESSION_STATE_COMPLETED;
    case SessionState::kAborted:
      return v1::SESSION_STATE_ABORTED;
    case SessionState::kFailed:
      return v1::SESSION_STATE_FAILED;
  }
  return v1::SESSION_STATE_UNSPECIFIED;
}

SessionState FromProtoState(v1::SessionState state) {
  switch (state) {
    case v1::SESSION_STATE_RUNNING:
      return SessionState::kRunning;
    case v1::SESSION_STATE_PAUSING:
      return SessionState::kPausing;
    case v1::SESSION_STATE_PAUSED:
      return SessionState::kPaused;
    case v1::SESSION_STATE_AWAITING_OPERATOR:
      return SessionState::kAwaitingOperator;
    case v1::SESSION_STATE_COMPLETED:
      return SessionState::kCompleted;
    case v1::SESSION_STATE_ABORTED:
      return SessionState::kAborted;
    case v1::SESSION_STATE_FAILED:
      return SessionState::kFailed;
    default:
      return SessionState::kQueued;
  }
}

v1::ReadingKind ToProtoReadingKind(ReadingKind kind) {
  switch (kind) {
    case ReadingKind::kSample:
      return v1::READING_KIND_SAMPLE;
    case ReadingKind::kReference:
      return v1::READING_KIND_REFERENCE;
    case ReadingKind::kDark:
      return v1::READING_KIND_DARK;
  }
  return v1::READING_KIND_UNSPECIFIED;
}

std::optional<ReadingKind> FromProtoReadingKind(int kind) {
  switch (kind) {
    case v1::READING_KIND_SAMPLE:
      return ReadingKind::kSample;
    case v1::READING_KIND_REFERENCE:
      return ReadingKind::kReference;
    case v1::READING_KIND_DARK:
      return ReadingKind::kDark;
    default:
      return std::nullopt;
  }
}

v1::Quantity ToProtoQuantity(Quantity quantity) {
  switch (quantity) {
    case Quantity::kRadiance:
      return v1::QUANTITY_RADIANCE;
    case Quantity::kReflectance:
      return v1::QUANTITY_REFLECTANCE;
    case Quantity::kBrdf:
      break;
  }
  return v1::QUANTITY_BRDF;
}

std::optional<Quantity> FromProtoQuantity(int quantity) {
  switch (quantity) {
    case v1::QUANTITY_UNSPECIFIED:
    case v1::QUANTITY_BRDF:
      return Quantity::kBrdf;
    case v1::QUANTITY_RADIANCE:
      return Quantity::kRadiance;
    case v1::QUANTITY_REFLECTANCE:
      return Quantity::kReflectance;
    default:
      return std::nullopt;
  }
}

v1::InterpolationMethod ToProtoMethod(interp::Method method) {
  switch (method) {
    case interp::Method::kOctant:
      return v1::INTERPOLATION_METHOD_OCTANT;
    case interp::Method::kDelaunay:
      return v1::INTERPOLATION_METHOD_DELAUNAY;
    case interp::Method::kNearest:
      return v1::INTERPOLATION_METHOD_NEAREST;
  }
  return v1::INTERPOLATION_METHOD_UNSPECIFIED;
}

std::optional<interp::Method> FromProtoMethod(int method) {
  switch (method) {
    case v1::INTERPOLATION_METHOD_UNSPECIFIED:
    case v1::INTERPOLATION_METHOD_OCTANT:
      return interp::Method::kOctant;
    case v1::INTERPOLATION_METHOD_DELAUNAY:
      return interp::Method::kDelaunay;
    case v1::INTERPOLATION_METHOD_NEAREST:
      return interp::Method::kNearest;
    default:
      return std::nullopt;
  }
}

std::optional<interp::Coordinates> FromProtoCoordinates(int coordinates) {
  switch (coordinates) {
    case v1::INTERPOLATION_COORDINATES_UNSPECIFIED:
    case v1::INTERPOLATION_COORDINATES_INCIDENCE:
      return interp::Coordinates::kIncidence;
    case v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE:
      return interp::Coordinates::kHalfDifference;
    default:
      return std::nullopt;
  }
}

std::optional<interp::Trend> FromProtoTrend(int trend) {
  switch (trend) {
    case v1::INTERPOLATION_TREND_UNSPECIFIED:
    case v1::INTERPOLATION_TREND_NONE:
      return interp::Trend::kNone;
    case v1::INTERPOLATION_TREND_BIVARIATE:
      return interp::Trend::kBivariate;
    default:
      return std::nullopt;
  }
}

v1::InterpolationStatus ToProtoInterpStatus(interp::InterpStatus status) {
  switch (status) {
    case interp::InterpStatus::kOk:
      return v1::INTERPOLATION_STATUS_OK;
    case interp::InterpStatus::kEmptyOctant:
      return v1::INTERPOLATION_STATUS_EMPTY_OCTANT;
    case interp::InterpStatus::kNoEnclosingSimplex:
      return v1::INTERPOLATION_STATUS_NO_ENCLOSING_SIMPLEX;
    case interp::InterpStatus::kOutsideHull:
      return v1::INTERPOLATION_STATUS_OUTSIDE_HULL;
  }
  return v1::INTERPOLATION_STATUS_UNSPECIFIED;
}

std::optional<PauseMode> FromProtoPauseMode(int mode) {
  switch (mode) {
    case v1::PAUSE_MODE_UNSPECIFIED:
    case v1::PAUSE_MODE_DEFERRED:
      return PauseMode::kDeferred;
    case v1::PAUSE_MODE_IMMEDIATE:
      return PauseMode::kImmediate;
    default:
      return std::nullopt;
  }
}

storage::StepKind ToStorageKind(v1::StepKind kind) {
  switch (kind) {
    case v1::STEP_KIND_MOVE:
      return storage::StepKind::kMove;
    case v1::STEP_KIND_PROMPT:
      return storage::StepKind::kPrompt;
    case v1::STEP_KIND_REFERENCE:
      return storage::StepKind::kReference;
    case v1::STEP_KIND_DARK:
      return storage::StepKind::kDark;
    default:
      return storage::StepKind::kSample;
  }
}

v1::StepKind ToProtoKind(storage::StepKind kind) {
  switch (kind) {
    case storage::StepKind::kMove:
      return v1::STEP_KIND_MOVE;
    case storage::StepKind::kPrompt:
      return v1::STEP_KIND_PROMPT;
    case storage::StepKind::kReference:
      return v1::STEP_KIND_REFERENCE;
    case storage::StepKind::kDark:
      return v1::STEP_KIND_DARK;
    case storage::StepKind::kSample:
      return v1::STEP_KIND_SAMPLE;
  }
  return v1::STEP_KIND_UNSPECIFIED;
}

std::string PromptKindWord(v1::PromptKind kind) {
  constexpr std::string_view kPrefix = "PROMPT_KIND_";
  std::string name = v1::PromptKind_Name(kind);
  if (name.rfind(kPrefix, 0) == 0) name = name.substr(kPrefix.size());
  for (char& ch : name) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return name;
}

v1::PromptKind ParsePromptKindWord(const std::string& word) {
  std::string name = "PROMPT_KIND_";
  for (char ch : word) name += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  v1::PromptKind kind = v1::PROMPT_KIND_UNSPECIFIED;
  if (!v1::PromptKind_Parse(name, &kind)) return v1::PROMPT_KIND_UNSPECIFIED;
  return kind;
}

std::string PlanKindWord(const v1::Plan& plan) {
  switch (plan.method_case()) {
    case v1::Plan::kSampleRotation:
      return "sample_rotation";
    case v1::Plan::kSampleFixed:
      return "sample_fixed";
    case v1::Plan::kPoseList:
      return "pose_list";
    case v1::Plan::kAdaptive:
      return "adaptive";
    default:
      return "";
  }
}

}  // namespace brdf::daemon
