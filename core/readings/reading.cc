#include "core/readings/reading.h"

#include <cmath>

namespace brdf {

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
