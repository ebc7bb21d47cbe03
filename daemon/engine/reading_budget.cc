#include "daemon/engine/reading_budget.h"

#include <cmath>
#include <iterator>
#include <utility>

#include "core/uncertainty/lamp_drift.h"

namespace brdf::daemon {
namespace {

double ResolutionU(const AxisSettings& axis) {
  return axis.counts_per_degree > 0 ? 1.0 / axis.counts_per_degree / std::sqrt(12.0) : 0.0;
}

std::vector<double> Net(const std::vector<double>& signal, const std::vector<double>* dark) {
  std::vector<double> net = signal;
  if (dark != nullptr && dark->size() == net.size()) {
    for (std::size_t b = 0; b < net.size(); ++b) net[b] -= (*dark)[b];
  }
  return net;
}

}  // namespace

std::optional<ReadingBudgetSettings> ReadingBudgetSettingsFrom(const Config& config) {
  const UncertaintyConfig& u = config.uncertainty;
  if (!u.enabled) return std::nullopt;
  ReadingBudgetSettings s;
  s.white_reflectance_u = config.sample.white_reflectance_uncertainty;
  s.lamp_drift_per_hour = u.lamp_drift_per_hour;
  s.terms.wavelength_nm = u.wavelength_nm;
  s.terms.stray_light = u.stray_light;
  s.terms.meter.full_scale = u.meter_full_scale;
  s.terms.meter.full_well_counts = u.meter_full_well_counts;
  s.terms.meter.read_noise_counts = u.meter_read_noise_counts;
  s.terms.meter.adaptive_fill = u.meter_adaptive_fill;
  s.terms.meter.gain_repeatability = u.meter_gain_repeatability;
  const AxisSettings* axes[] = {&config.stage.alpha, &config.stage.beta, &config.stage.gamma,
                                &config.stage.delta};
  for (std::size_t a = 0; a < 4; ++a) {
    s.terms.stage.repeatability_deg[a] =
        std::hypot(u.stage_repeatability_deg, ResolutionU(*axes[a]));
    s.terms.stage.alignment_deg[a] = u.stage_alignment_deg;
  }
  return s;
}

ReadingBudgeter::ReadingBudgeter(ReadingBudgetSettings settings, std::int64_t session,
                                 double white_reflectance, std::optional<Spectrum> white_spectrum,
                                 std::optional<double> white_u, int averages)
    : settings_(std::move(settings)),
      session_(session),
      white_reflectance_(white_reflectance),
      white_spectrum_(std::move(white_spectrum)),
      white_u_(white_u.value_or(settings_.white_reflectance_u)),
      averages_(std::max(averages, 1)) {}

void ReadingBudgeter::Observe(const storage::ReadingRecord& r, double time_s) {
  const Kept kept{r.spectrum, r.integration_ms, r.directions.theta_i, time_s, std::nullopt};
  if (r.kind == ReadingKind::kReference) references_[r.id] = kept;
  if (r.kind != ReadingKind::kDark) return;
  darks_[r.id] = kept;
  if (!references_.empty() && !references_.rbegin()->second.dark.has_value()) {
    references_.rbegin()->second.dark = r.id;
  }
}

Result<std::optional<uncertainty::LampDrift>> ReadingBudgeter::DriftOf(std::int64_t reference,
                                                                       double time_s) const {
  auto observation = [this](const Kept& k) {
    const auto dark = k.dark.has_value() ? darks_.find(*k.dark) : darks_.end();
    const std::vector<double>* d = dark != darks_.end() ? &dark->second.radiance : nullptr;
    return uncertainty::ReferenceObservation{Net(k.radiance, d), k.theta_i, k.time_s};
  };
  const auto own = references_.find(reference);
  std::optional<uncertainty::ReferenceObservation> previous, next;
  if (own != references_.begin()) previous = observation(std::prev(own)->second);
  if (std::next(own) != references_.end()) next = observation(std::next(own)->second);
  return uncertainty::DriftOfReading(time_s, observation(own->second), previous, next,
                                     settings_.lamp_drift_per_hour);
}

Result<std::vector<double>> ReadingBudgeter::WhiteOn(const WavelengthGrid& grid) const {
  if (!white_spectrum_.has_value()) return std::vector<double>{white_reflectance_};
  BRDF_ASSIGN_OR_RETURN(Spectrum on_grid, Resample(*white_spectrum_, grid));
  return std::move(on_grid.values);
}

Result<uncertainty::ReadingBudget> ReadingBudgeter::Estimate(
    const storage::ReadingRecord& sample, double time_s,
    std::optional<uncertainty::PoseGradient> pose_gradient) const {
  const std::string name = "reading at step " + std::to_string(sample.step_index);
  if (!sample.reference_reading_id.has_value()) {
    return FailedPrecondition(name + " names no reference reading");
  }
  const auto ref = references_.find(*sample.reference_reading_id);
  if (ref == references_.end()) {
    return FailedPrecondition(name + ": its reference " +
                              std::to_string(*sample.reference_reading_id) + " is not known");
  }
  uncertainty::BudgetInputs in;
  in.session_id = session_;
  in.grid = sample.grid;
  in.sample = {0, sample.spectrum, sample.integration_ms, averages_};
  in.reference = {ref->first, ref->second.radiance, ref->second.integration_ms, averages_};
  if (sample.dark_reading_id.has_value()) {
    const auto dark = darks_.find(*sample.dark_reading_id);
    if (dark == darks_.end()) return FailedPrecondition(name + ": its dark is not known");
    in.dark = uncertainty::MeasuredSignal{dark->first, dark->second.radiance,
                                          dark->second.integration_ms, averages_};
  }
  BRDF_ASSIGN_OR_RETURN(in.white_reflectance, WhiteOn(sample.grid));
  in.white_reflectance_u = {white_u_};
  in.theta_i_deg = sample.directions.theta_i;
  in.theta_r_deg = ref->second.theta_i;
  BRDF_ASSIGN_OR_RETURN(in.drift, DriftOf(ref->first, time_s));
  in.terms = settings_.terms;
  in.pose_gradient = std::move(pose_gradient);
  return uncertainty::EstimateReadingBudget(in);
}

std::vector<std::pair<std::int64_t, uncertainty::ReadingBudget>> ReadingBudgeter::EstimateSession(
    const std::vector<storage::ReadingRecord>& samples) const {
  // First the values (the gradient needs every neighbour's), then the budgets with the gradient.
  std::vector<const storage::ReadingRecord*> known;
  std::vector<uncertainty::PosedValue> posed;
  for (const storage::ReadingRecord& r : samples) {
    Result<uncertainty::ReadingBudget> first = Estimate(r, r.recorded_at);
    if (!first.ok()) continue;
    known.push_back(&r);
    posed.push_back({r.pose, r.directions.theta_i, std::move(first->value)});
  }
  const std::vector<uncertainty::PoseGradient> gradients =
      uncertainty::EstimatePoseGradients(posed);
  std::vector<std::pair<std::int64_t, uncertainty::ReadingBudget>> out;
  for (std::size_t i = 0; i < known.size(); ++i) {
    Result<uncertainty::ReadingBudget> budget =
        Estimate(*known[i], known[i]->recorded_at, gradients[i]);
    if (budget.ok()) out.emplace_back(known[i]->id, std::move(*budget));
  }
  return out;
}

}  // namespace brdf::daemon
