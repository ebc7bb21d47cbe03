#include "daemon/engine/steps.h"

#include <google/protobuf/util/time_util.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <string_view>

namespace brdf::daemon {

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
    default:
      return "";
  }
}

storage::StepRecord ToStepRecord(const plan::Step& step) {
  storage::StepRecord r;
  r.step_index = step.index;
  r.kind = ToStorageKind(step.kind);
  r.pose = step.pose;
  if (step.kind == v1::STEP_KIND_PROMPT) {
    r.prompt = step.prompt_text;
    r.prompt_kind = PromptKindWord(step.prompt);
    r.expected_action = step.expected_action;
  }
  r.target = step.target;
  r.label = step.label;
  return r;
}

plan::Step ToPlanStep(const storage::StepRecord& record) {
  plan::Step s;
  s.index = record.step_index;
  s.kind = ToProtoKind(record.kind);
  s.pose = record.pose;
  if (record.prompt_kind.has_value()) s.prompt = ParsePromptKindWord(*record.prompt_kind);
  s.prompt_text = record.prompt.value_or("");
  s.expected_action = record.expected_action.value_or("");
  s.label = record.label;
  s.target = record.target;
  return s;
}

std::vector<plan::Step> ToPlanSteps(const std::vector<storage::StepRecord>& records) {
  std::vector<plan::Step> steps;
  steps.reserve(records.size());
  for (const auto& r : records) steps.push_back(ToPlanStep(r));
  return steps;
}

v1::Prompt ToPrompt(const storage::StepRecord& step) {
  v1::Prompt p;
  p.set_step_index(step.step_index);
  p.set_kind(step.prompt_kind.has_value() ? ParsePromptKindWord(*step.prompt_kind)
                                          : v1::PROMPT_KIND_UNSPECIFIED);
  p.set_text(step.prompt.value_or(step.label));
  p.set_expected_action(step.expected_action.value_or(""));
  *p.mutable_pose() = ToProtoPose(step.pose);
  if (step.target.has_value()) *p.mutable_target() = ToProtoDirections(*step.target);
  return p;
}

google::protobuf::Timestamp ToTimestamp(storage::UnixSeconds seconds) {
  const double whole = std::floor(seconds);
  google::protobuf::Timestamp t;
  t.set_seconds(static_cast<std::int64_t>(whole));
  t.set_nanos(static_cast<std::int32_t>(std::lround((seconds - whole) * 1e9) % 1000000000));
  return t;
}

google::protobuf::Timestamp NowTimestamp() {
  return google::protobuf::util::TimeUtil::NanosecondsToTimestamp(
      std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::system_clock::now().time_since_epoch())
          .count());
}

v1::Pose ToProtoPose(const Pose& pose) {
  v1::Pose p;
  p.set_alpha(pose.alpha);
  p.set_beta(pose.beta);
  p.set_gamma(pose.gamma);
  p.set_delta(pose.delta);
  return p;
}

v1::Directions ToProtoDirections(const Directions& d) {
  v1::Directions p;
  p.set_theta_i(d.theta_i);
  p.set_phi_i(d.phi_i);
  p.set_theta_o(d.theta_o);
  p.set_phi_o(d.phi_o);
  return p;
}

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

}  // namespace brdf::daemon
