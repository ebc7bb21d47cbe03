#include "core/readings/reading.h"

#include <cmath>

namespace brdf {

std::string IntegrationNoteOf(std::string_view note) {
  // The quality policy's words when it changes the integration time (drivers/pr650/
  // quality_codes.cc: DecideQuality).
  static constexpr std::string_view kChanges[] = {"integration halved", "integration doubled"};
  std::string out;
  while (!note.empty()) {
    const std::size_t end = note.find("; ");
    const std::string_view clause = note.substr(0, end);
    for (std::string_view change : kChanges) {
      if (clause.find(change) == std::string_view::npos) continue;
      if (!out.empty()) out += "; ";
      out += clause;
      break;
    }
    note = end == std::string_view::npos ? std::string_view() : note.substr(end + 2);
  }
  return out;
}

const char* ReadingKindName(ReadingKind kind) {
  switch (kind) {
    case ReadingKind::kSample:
      return "sample";
    case ReadingKind::kReference:
      return "reference";
    case ReadingKind::kDark:
      return "dark";
  }
  return "unknown";
}

double WhiteReflectanceOf(const SessionReadings& session) {
  return session.white_reflectance.value_or(kWhiteStandardReflectance);
}

bool HasSeveralDialPositions(const SessionReadings& session) {
  const Reading* first = nullptr;
  for (const Reading& r : session.readings) {
    if (r.kind != ReadingKind::kSample) continue;
    if (first == nullptr) {
      first = &r;
    } else if (std::abs(r.pose.gamma - first->pose.gamma) > 1e-9) {
      return true;
    }
  }
  return false;
}

}  // namespace brdf
