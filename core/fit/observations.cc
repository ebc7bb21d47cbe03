#include "core/fit/observations.h"

#include <cmath>
#include <set>
#include <string>

#include "core/geometry.h"

namespace brdf::fit {

Status Observations::Validate(const std::string& where, const IsoDirection& at,
                              std::span<const double> brdf, std::span<const double> u,
                              const char* what) const {
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
    return InvalidArgument(where + ": " + std::to_string(u.size()) + " " + what +
                           " for a grid of " + std::to_string(grid_.count) + " bands");
  }
  for (std::size_t b = 0; b < u.size(); ++b) {
    if (!std::isfinite(u[b]) || u[b] <= 0) {
      return InvalidArgument(where + ": the " + what + " at " + std::to_string(grid_.at(b)) +
                             " nm is not a positive number (give none for an unweighted value)");
    }
  }
  return Status::Ok();
}

void Observations::Append(const IsoDirection& at, std::span<const double> brdf,
                          std::span<const double> independent, std::vector<SharedTerm> shared) {
  directions_.push_back(at);
  values_.insert(values_.end(), brdf.begin(), brdf.end());
  if (independent.empty()) {
    uncertainties_.insert(uncertainties_.end(), grid_.count, std::nan(""));
    independent_.insert(independent_.end(), grid_.count, std::nan(""));
  } else {
    independent_.insert(independent_.end(), independent.begin(), independent.end());
    for (std::size_t b = 0; b < grid_.count; ++b) {
      double v = independent[b] * independent[b];
      for (const SharedTerm& t : shared) v += t.contribution[b] * t.contribution[b];
      uncertainties_.push_back(std::sqrt(v));
    }
    ++with_uncertainty_;
  }
  shared_.push_back(std::move(shared));
}

Status Observations::Add(const IsoDirection& at, std::span<const double> brdf,
                         std::span<const double> u) {
  const std::string where = "observation " + std::to_string(directions_.size());
  BRDF_RETURN_IF_ERROR(Validate(where, at, brdf, u, "uncertainties"));
  Append(at, brdf, u, {});
  return Status::Ok();
}

Status Observations::AddWithSharedTerms(const IsoDirection& at, std::span<const double> brdf,
                                        std::span<const double> independent,
                                        std::span<const SharedContribution> shared) {
  const std::string where = "observation " + std::to_string(directions_.size());
  if (independent.empty()) {
    return InvalidArgument(where +
                           ": no independent uncertainty (use Add for a value without one)");
  }
  BRDF_RETURN_IF_ERROR(Validate(where, at, brdf, independent, "independent uncertainties"));
  std::set<std::string> named;
  for (const SharedContribution& s : shared) {
    if (s.source.empty())
      return InvalidArgument(where + ": a shared contribution without a source");
    if (!named.insert(s.source).second) {
      return InvalidArgument(where + ": the shared source '" + s.source +
                             "' is named twice (add its contributions first)");
    }
    if (s.contribution.size() != grid_.count) {
      return InvalidArgument(where + ": shared source '" + s.source + "' has " +
                             std::to_string(s.contribution.size()) +
                             " contributions for a grid of " + std::to_string(grid_.count) +
                             " bands");
    }
    for (std::size_t b = 0; b < grid_.count; ++b) {
      if (!std::isfinite(s.contribution[b])) {
        return InvalidArgument(where + ": shared source '" + s.source + "' at " +
                               std::to_string(grid_.at(b)) + " nm is not a finite number");
      }
    }
  }
  std::vector<SharedTerm> terms;
  for (const SharedContribution& s : shared) {
    const auto [it, added] = source_index_.emplace(s.source, source_names_.size());
    if (added) source_names_.push_back(s.source);
    terms.push_back({it->second, s.contribution});
  }
  Append(at, brdf, independent, std::move(terms));
  return Status::Ok();
}

Weighting Observations::weighting() const {
  if (!weighted()) return Weighting::kUnweighted;
  return source_names_.empty() ? Weighting::kIndependent : Weighting::kGeneralised;
}

std::string WeightingText(Weighting weighting, std::size_t shared_terms) {
  switch (weighting) {
    case Weighting::kGeneralised:
      return "GLS with " + std::to_string(shared_terms) + " shared terms";
    case Weighting::kIndependent:
      return "weighted, independent";
    case Weighting::kUnweighted:
      break;
  }
  return "unweighted: readings without a budget";
}

}  // namespace brdf::fit
