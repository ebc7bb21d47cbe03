#include "core/fit/observations.h"

#include <cmath>
#include <string>

#include "core/geometry.h"

namespace brdf::fit {

Status Observations::Add(const IsoDirection& at, std::span<const double> brdf) {
  const std::string where = "observation " + std::to_string(directions_.size());
  BRDF_RETURN_IF_ERROR(ValidateIsoDirection(at).WithContext(where));
  if (brdf.size() != grid_.count) {
    return InvalidArgument(where + ": " + std::to_string(brdf.size()) + " values for a grid of " +
                           std::to_string(grid_.count) + " bands");
  }
  for (std::size_t b = 0; b < brdf.size(); ++b) {
    if (!std::isfinite(brdf[b])) {
      return InvalidArgument(where + ": the value at " + std::to_string(grid_.at(b)) +
                             " nm is not a finite number");
    }
  }
  directions_.push_back(at);
  values_.insert(values_.end(), brdf.begin(), brdf.end());
  return Status::Ok();
}

}  // namespace brdf::fit
