#include "core/export/session_data.h"

#include <cmath>
#include <utility>

#include "core/geometry.h"
#include "core/readings/derive.h"

namespace brdf::exports {
namespace {

// The standard uncertainty of `quantity` for one sample (DerivedSample::u), or empty.
std::vector<double> UncertaintyOf(const Reading& r, Quantity quantity, const SampleQuantities& q) {
  const std::size_t n = q.of(quantity).size();
  if (quantity == Quantity::kBrdf) {
    return r.brdf_u.size() == n ? r.brdf_u : std::vector<double>();
  }
  if (quantity != Quantity::kReflectance || r.brdf_u_of_ratio.size() != n ||
      !q.has(Quantity::kBrdf)) {
    return {};
  }
  const std::vector<double>& f = q.of(Quantity::kBrdf);
  const std::vector<double>& refl = q.of(Quantity::kReflectance);
  std::vector<double> u(n);
  for (std::size_t b = 0; b < n; ++b) {
    u[b] = f[b] != 0 ? r.brdf_u_of_ratio[b] * std::abs(refl[b] / f[b]) : std::nan("");
  }
  return u;
}

// The reading's budget when it is of the BRDF and the samples are (else null).
std::shared_ptr<const uncertainty::LoadedBudget> BrdfBudgetOf(const Reading& r, Quantity quantity) {
  return quantity == Quantity::kBrdf ? r.budget : nullptr;
}

}  // namespace

Result<DerivedSamples> DeriveSamples(const Session& session, Quantity quantity,
                                     const DeriveOptions& options) {
  const double white = WhiteReflectanceOf(session);
  if (!std::isfinite(white) || white <= 0) {
    return InvalidArgument("session " + std::to_string(session.id) +
                           ": white reflectance ρw = " + std::to_string(white) +
                           " is not a positive number; fix the session's white_reflectance");
  }
  ReadingDeriver deriver(white, session.white_reflectance_spectrum);
  DerivedSamples out;
  out.quantity = quantity;
  out.white_reflectance = white;
  std::size_t sample_readings = 0;
  for (const Reading& r : session.readings) {
    if (r.kind == ReadingKind::kSample) {
      ++sample_readings;
      if (options.exclude_flagged && r.flagged) {
        out.skipped.push_back({r.id, "reading " + std::to_string(r.id) +
                                         ": flagged by the quality policy (left out on request)"});
        continue;
      }
    }
    std::optional<SampleQuantities> derived = deriver.Fold(r);
    if (!derived.has_value()) continue;  // a reference or a dark, kept for the samples after it
    if (!derived->has(quantity)) {
      out.skipped.push_back({r.id, derived->reason(quantity)});
      continue;
    }
    std::vector<double> u = UncertaintyOf(r, quantity, *derived);
    out.samples.push_back(DerivedSample{r.id, r.directions, ToIsotropic(r.directions),
                                        std::move(derived->values[static_cast<int>(quantity)]),
                                        std::move(u), BrdfBudgetOf(r, quantity)});
  }
  if (sample_readings == 0) {
    return FailedPrecondition("session " + std::to_string(session.id) +
                              " has no sample readings (empty session): measure it first, or "
                              "pick another session");
  }
  if (out.samples.empty()) {
    return FailedPrecondition("session " + std::to_string(session.id) + ": none of its " +
                              std::to_string(sample_readings) + " sample readings gives a " +
                              QuantityName(quantity) +
                              "; the first: " + out.skipped.front().reason);
  }
  out.grid = *deriver.grid();
  return out;
}

Result<std::shared_ptr<const interp::SampleSet>> ToSampleSet(const DerivedSamples& derived) {
  auto set = std::make_shared<interp::SampleSet>(3, static_cast<int>(derived.grid.count));
  for (const DerivedSample& s : derived.samples) {
    const double coords[3] = {s.iso.theta_i, s.iso.theta_o, s.iso.phi};
    BRDF_RETURN_IF_ERROR(set->Add(s.reading_id, coords, s.values));
  }
  return std::shared_ptr<const interp::SampleSet>(std::move(set));
}

}  // namespace brdf::exports
