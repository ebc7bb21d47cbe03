#include "storage/records.h"

#include <array>
#include <utility>

namespace brdf::storage {
namespace {

template <typename E, std::size_t N>
using Names = std::array<std::pair<E, std::string_view>, N>;

constexpr Names<StepKind, 5> kStepKinds{{
    {StepKind::kMove, "move"},
    {StepKind::kPrompt, "prompt"},
    {StepKind::kReference, "reference"},
    {StepKind::kDark, "dark"},
    {StepKind::kSample, "sample"},
}};
constexpr Names<StepState, 3> kStepStates{{
    {StepState::kPending, "pending"},
    {StepState::kDone, "done"},
    {StepState::kSkipped, "skipped"},
}};
constexpr Names<ReadingKind, 3> kReadingKinds{{
    {ReadingKind::kSample, "sample"},
    {ReadingKind::kReference, "reference"},
    {ReadingKind::kDark, "dark"},
}};

template <typename E, std::size_t N>
std::string_view NameOf(const Names<E, N>& names, E value) {
  for (const auto& [v, name] : names) {
    if (v == value) return name;
  }
  return "unknown";
}

template <typename E, std::size_t N>
Result<E> Parse(const Names<E, N>& names, std::string_view text, std::string_view what) {
  for (const auto& [v, name] : names) {
    if (name == text) return v;
  }
  std::string accepted;
  for (const auto& [v, name] : names) {
    if (!accepted.empty()) accepted += ", ";
    accepted += name;
  }
  return InvalidArgument("unknown " + std::string(what) + " \"" + std::string(text) +
                         "\" (expected one of: " + accepted + ")");
}

}  // namespace

std::string_view ToString(SessionState state) {
  return SessionStateName(state);
}
std::string_view ToString(StepKind kind) {
  return NameOf(kStepKinds, kind);
}
std::string_view ToString(StepState state) {
  return NameOf(kStepStates, state);
}
std::string_view ToString(ReadingKind kind) {
  return NameOf(kReadingKinds, kind);
}

Result<StepKind> ParseStepKind(std::string_view text) {
  return Parse(kStepKinds, text, "step kind");
}
Result<StepState> ParseStepState(std::string_view text) {
  return Parse(kStepStates, text, "step state");
}
Result<ReadingKind> ParseReadingKind(std::string_view text) {
  return Parse(kReadingKinds, text, "reading kind");
}

bool IsActive(SessionState state) {
  return state == SessionState::kRunning || state == SessionState::kPausing ||
         state == SessionState::kAwaitingOperator;
}

std::optional<ReadingKind> ReadingKindFor(StepKind kind) {
  switch (kind) {
    case StepKind::kReference:
      return ReadingKind::kReference;
    case StepKind::kDark:
      return ReadingKind::kDark;
    case StepKind::kSample:
      return ReadingKind::kSample;
    case StepKind::kMove:
    case StepKind::kPrompt:
      return std::nullopt;
  }
  return std::nullopt;
}

StepTally TallySteps(std::span<const StepRecord> steps) {
  StepTally tally;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const bool pending = steps[i].state == StepState::kPending;
    if (steps[i].kind == StepKind::kSample) {
      ++tally.samples;
      if (!pending) ++tally.done_samples;
    }
    if (pending && tally.first_pending < 0) tally.first_pending = static_cast<int>(i);
  }
  return tally;
}

}  // namespace brdf::storage
