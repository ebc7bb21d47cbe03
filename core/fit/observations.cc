#include "core/fit/observations.h"

#include <cmath>
#include <string>

#include "core/geometry.h"

namespace brdf::fit {

Status Observations::Add(const IsoDirection& at, std::span<const double> brdf,
                         std::span<const double> u) {
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
  if (!u.empty() && u.size() != grid_.count) {
    return InvalidArgument(where + ": " + std::to_string(u.size()) +
                           " uncertainties for a grid of " + std::to_string(grid_.count) +
                           " bands");
  }
  for (std::size_t b = 0; b < u.size(); ++b) {
    if (!std::isfinite(u[b]) || u[b] <= 0) {
      return InvalidArgument(where + ": the uncertainty at " + std::to_string(grid_.at(b)) +
                             " nm is not a positive number (give none for an unweighted value)");
    }
  }
  directions_.push_back(at);
  values_.insert(values_.end(), brdf.begin(), brdf.end());
  if (u.empty()) {
    uncertainties_.insert(uncertainties_.end(), grid_.count, std::nan(""));
  } else {
    uncertainties_.insert(uncertainties_.end(), u.begin(), u.end());
    ++with_uncertainty_;
  }
  return Status::Ok();
}

}  // namespace brdf::fit
