#include "core/uncertainty/lamp_drift.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace brdf::uncertainty {
namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

Result<double> Cosine(double theta_deg) {
  if (!std::isfinite(theta_deg) || theta_deg < 0 || theta_deg >= 90) {
    return InvalidArgument("a white reference's θr must lie in [0°, 90°), got " +
                           std::to_string(theta_deg));
  }
  return std::cos(theta_deg * kRadPerDeg);
}

double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  return (*std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)) + upper) / 2;
}

Status CheckOrder(double earlier, double later, const char* what) {
  if (std::isfinite(earlier) && std::isfinite(later) && later > earlier) return Status::Ok();
  return InvalidArgument(std::string("lamp drift: ") + what + " must be taken after the other");
}

}  // namespace

Result<double> RelativeChange(const ReferenceObservation& from, const ReferenceObservation& to) {
  if (from.net.size() != to.net.size()) {
    return InvalidArgument("lamp drift: the two references have " +
                           std::to_string(from.net.size()) + " and " +
                           std::to_string(to.net.size()) + " bands");
  }
  BRDF_ASSIGN_OR_RETURN(double cos_from, Cosine(from.theta_r_deg));
  BRDF_ASSIGN_OR_RETURN(double cos_to, Cosine(to.theta_r_deg));
  std::vector<double> ratios;
  for (std::size_t b = 0; b < from.net.size(); ++b) {
    if (from.net[b] > 0 && to.net[b] > 0 && std::isfinite(from.net[b]) &&
        std::isfinite(to.net[b])) {
      ratios.push_back((to.net[b] / cos_to) / (from.net[b] / cos_from) - 1.0);
    }
  }
  if (ratios.empty()) {
    return InvalidArgument("lamp drift: no band where both references have light");
  }
  return Median(std::move(ratios));
}

Result<std::optional<LampDrift>> DriftOfReading(double time_s, const ReferenceObservation& own,
                                                const std::optional<ReferenceObservation>& previous,
                                                const std::optional<ReferenceObservation>& next,
                                                std::optional<double> rate_per_hour) {
  const double since = std::max(0.0, time_s - own.time_s);
  if (next.has_value()) {
    BRDF_RETURN_IF_ERROR(CheckOrder(own.time_s, next->time_s, "the next reference"));
    BRDF_ASSIGN_OR_RETURN(double change, RelativeChange(own, *next));
    return std::optional<LampDrift>(LampDrift{change, since / (next->time_s - own.time_s)});
  }
  if (previous.has_value()) {
    BRDF_RETURN_IF_ERROR(CheckOrder(previous->time_s, own.time_s, "the reading's reference"));
    BRDF_ASSIGN_OR_RETURN(double change, RelativeChange(*previous, own));
    return std::optional<LampDrift>(LampDrift{change, since / (own.time_s - previous->time_s)});
  }
  if (rate_per_hour.has_value()) {
    if (!std::isfinite(*rate_per_hour)) {
      return InvalidArgument("lamp drift: the configured rate per hour is not finite");
    }
    return std::optional<LampDrift>(LampDrift{*rate_per_hour, since / 3600.0});
  }
  return std::optional<LampDrift>();
}

}  // namespace brdf::uncertainty
