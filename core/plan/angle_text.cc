#include "core/plan/angle_text.h"

#include <cmath>
#include <cstdio>

namespace brdf::plan {

std::string Num(double value) {
  // Rounding noise of the kinematics (2e-15°) prints as 0; no "-0" either.
  if (std::fabs(value) < 1e-9) value = 0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

std::string Deg(double value) {
  return Num(value) + "°";
}

}  // namespace brdf::plan
