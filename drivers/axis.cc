#include "drivers/rotation_stage.h"

namespace brdf::drivers {

const char* AxisName(Axis axis) {
  switch (axis) {
    case Axis::kAlpha:
      return "alpha";
    case Axis::kBeta:
      return "beta";
    case Axis::kGamma:
      return "gamma";
    case Axis::kDelta:
      return "delta";
  }
  return "unknown";
}

}  // namespace brdf::drivers
