#include "core/uncertainty/budget.h"

#include <cmath>
#include <utility>

namespace brdf::uncertainty {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerDeg = kPi / 180.0;
constexpr std::array<const char*, 4> kAxisNames = {"alpha", "beta", "gamma", "delta"};

// A per-band input given either per band or as one value for every band.
double At(const std::vector<double>& v, std::size_t b) {
  return v.size() == 1 ? v[0] : v[b];
}

// The measurement equation's parts per band, at the estimates.
struct Evaluation {
  std::vector<double> k;        // K (1 for reflectance)
  std::vector<double> ref_net;  // I0 − D
  std::vector<double> ratio;    // R = (I − D) / (I0 − D)
  std::vector<double> value;    // f = K · R
};

Status CheckSize(const std::vector<double>& v, std::size_t n, const std::string& what,
                 bool one_allowed) {
  if (v.size() == n || (one_allowed && v.size() == 1)) return Status::Ok();
  return InvalidArgument(what + " has " + std::to_string(v.size()) + " values; the grid has " +
                         std::to_string(n) + " bands" +
                         (one_allowed ? " (or give one value)" : ""));
}

Status CheckNonNegative(const std::vector<double>& v, const std::string& what) {
  for (double x : v) {
    if (!std::isfinite(x) || x < 0) return InvalidArgument(what + " must be finite and ≥ 0");
  }
  return Status::Ok();
}

Status CheckAngle(double deg, const std::string& what) {
  if (std::isfinite(deg) && deg >= 0 && deg < 90) return Status::Ok();
  return InvalidArgument(what + " must lie in [0°, 90°), got " + std::to_string(deg));
}

Status CheckTerms(const BudgetInputs& in) {
  const BudgetTerms& t = in.terms;
  if (!std::isfinite(t.wavelength_nm) || t.wavelength_nm < 0) {
    return InvalidArgument("the wavelength scale's uncertainty must be finite and ≥ 0 nm");
  }
  if (!std::isfinite(t.stray_light) || t.stray_light < 0) {
    return InvalidArgument("the stray light's uncertainty must be finite and ≥ 0");
  }
  for (int a = 0; a < 4; ++a) {
    const std::string axis = kAxisNames[a];
    if (!std::isfinite(t.stage.repeatability_deg[a]) || t.stage.repeatability_deg[a] < 0 ||
        !std::isfinite(t.stage.alignment_deg[a]) || t.stage.alignment_deg[a] < 0) {
      return InvalidArgument("the stage's uncertainty on " + axis + " must be finite and ≥ 0°");
    }
  }
  if (in.drift.has_value() && (!std::isfinite(in.drift->change) ||
                               !std::isfinite(in.drift->share) || in.drift->share < 0)) {
    return InvalidArgument("the lamp drift's change must be finite and its share ≥ 0");
  }
  return CheckMeterNoiseModel(t.meter);
}

Status CheckInputs(const BudgetInputs& in) {
  if (in.quantity != Quantity::kBrdf && in.quantity != Quantity::kReflectance) {
    return InvalidArgument("a reading's budget is for the BRDF or the reflectance, not " +
                           std::string(QuantityName(in.quantity)));
  }
  if (!in.grid.valid()) return InvalidArgument("the wavelength grid is not valid");
  const std::size_t n = in.grid.count;
  Status s = CheckSize(in.sample.radiance, n, "the sample reading", false);
  if (s.ok()) s = CheckSize(in.reference.radiance, n, "the reference reading", false);
  if (s.ok() && in.dark.has_value()) s = CheckSize(in.dark->radiance, n, "the dark reading", false);
  if (s.ok() && in.quantity == Quantity::kBrdf) {
    s = CheckSize(in.white_reflectance, n, "ρw", true);
    if (s.ok()) s = CheckSize(in.white_reflectance_u, n, "u(ρw)", true);
    if (s.ok()) s = CheckNonNegative(in.white_reflectance_u, "u(ρw)");
    for (double rho : in.white_reflectance) {
      if (s.ok() && (!std::isfinite(rho) || rho <= 0)) s = InvalidArgument("ρw must be > 0");
    }
    if (s.ok()) s = CheckAngle(in.theta_i_deg, "θi");
    if (s.ok()) s = CheckAngle(in.theta_r_deg, "θr (the reference's incidence)");
  }
  if (s.ok() && in.pose_gradient.has_value()) {
    for (int a = 0; a < 4 && s.ok(); ++a) {
      const std::vector<double>& g = (*in.pose_gradient)[a];
      if (g.empty()) continue;  // that axis: not estimated
      s = CheckSize(g, n, std::string("the gradient along ") + kAxisNames[a], false);
      for (double x : g) {
        if (s.ok() && !std::isfinite(x)) {
          s = InvalidArgument(std::string("the gradient along ") + kAxisNames[a] +
                              " must be finite");
        }
      }
    }
  }
  return s.ok() ? CheckTerms(in) : s;
}

Result<Evaluation> Evaluate(const BudgetInputs& in) {
  const std::size_t n = in.grid.count;
  const bool brdf = in.quantity == Quantity::kBrdf;
  const double cosine_ratio =
      brdf ? std::cos(in.theta_r_deg * kRadPerDeg) / std::cos(in.theta_i_deg * kRadPerDeg) : 1.0;
  Evaluation e;
  for (std::size_t b = 0; b < n; ++b) {
    const double dark = in.dark.has_value() ? in.dark->radiance[b] : 0.0;
    const double ref_net = in.reference.radiance[b] - dark;
    if (!std::isfinite(ref_net) || ref_net <= 0) {
      return InvalidArgument("the reference is too dark at " + std::to_string(in.grid.at(b)) +
                             " nm (band " + std::to_string(b) + "): I0 − D ≤ 0");
    }
    const double k = brdf ? At(in.white_reflectance, b) / kPi * cosine_ratio : 1.0;
    const double ratio = (in.sample.radiance[b] - dark) / ref_net;
    e.k.push_back(k);
    e.ref_net.push_back(ref_net);
    e.ratio.push_back(ratio);
    e.value.push_back(k * ratio);
  }
  return e;
}

void Add(ReadingBudget& budget, std::string name, SharedThrough shared, std::vector<double> u) {
  budget.components.push_back(Component{std::move(name), shared, std::move(u)});
}

// sample_signal, reference_signal, dark_signal.
Status AddSignals(const BudgetInputs& in, const Evaluation& e, ReadingBudget& budget) {
  const MeterNoiseModel& meter = in.terms.meter;
  auto noise = [&](const MeasuredSignal& m,
                   const std::string& what) -> Result<std::vector<double>> {
    Result<std::vector<double>> u =
        SignalUncertainty(m.radiance, m.integration_ms, m.averages, meter);
    if (!u.ok()) return u.status().WithContext(what);
    return u;
  };
  Result<std::vector<double>> u_sample = noise(in.sample, "the sample reading");
  if (!u_sample.ok()) return u_sample.status();
  Result<std::vector<double>> u_ref = noise(in.reference, "the reference reading");
  if (!u_ref.ok()) return u_ref.status();
  const std::size_t n = e.value.size();
  std::vector<double> sample(n), reference(n);
  for (std::size_t b = 0; b < n; ++b) {
    sample[b] = e.k[b] / e.ref_net[b] * (*u_sample)[b];
    reference[b] = -e.value[b] / e.ref_net[b] * (*u_ref)[b];
  }
  Add(budget, "sample_signal", {}, std::move(sample));
  Add(budget, "reference_signal", {Sharing::kReferenceReading, in.reference.reading_id},
      std::move(reference));
  if (!in.dark.has_value()) {
    budget.not_estimated.push_back(
        "dark_signal: the reading names no dark reading (ambient light is not removed)");
    return Status::Ok();
  }
  Result<std::vector<double>> u_dark = noise(*in.dark, "the dark reading");
  if (!u_dark.ok()) return u_dark.status();
  std::vector<double> dark(n);
  for (std::size_t b = 0; b < n; ++b) {
    dark[b] = e.k[b] * (e.ratio[b] - 1.0) / e.ref_net[b] * (*u_dark)[b];
  }
  Add(budget, "dark_signal", {Sharing::kDarkReading, in.dark->reading_id}, std::move(dark));
  return Status::Ok();
}

// white_standard and reference_pose: the BRDF's scale only.
void AddWhiteAndReferencePose(const BudgetInputs& in, const Evaluation& e, ReadingBudget& budget) {
  if (in.quantity != Quantity::kBrdf) return;
  const std::size_t n = e.value.size();
  std::vector<double> white(n), pose(n);
  const double tan_r = std::tan(in.theta_r_deg * kRadPerDeg);
  const double u_theta_r = in.terms.stage.repeatability_deg[1] * kRadPerDeg;  // β sets θr
  for (std::size_t b = 0; b < n; ++b) {
    white[b] = e.value[b] / At(in.white_reflectance, b) * At(in.white_reflectance_u, b);
    pose[b] = e.value[b] * tan_r * u_theta_r;
  }
  Add(budget, "white_standard", {Sharing::kWhiteStandard, in.session_id}, std::move(white));
  Add(budget, "reference_pose", {Sharing::kReferenceReading, in.reference.reading_id},
      std::move(pose));
}

void AddDrift(const BudgetInputs& in, const Evaluation& e, ReadingBudget& budget) {
  if (!in.drift.has_value()) {
    budget.not_estimated.push_back(
        "lamp_drift: no second reference (or configured rate) to estimate the lamp's change");
    return;
  }
  std::vector<double> drift(e.value.size());
  for (std::size_t b = 0; b < drift.size(); ++b) {
    drift[b] = -e.value[b] * in.drift->share * in.drift->change;
  }
  Add(budget, "lamp_drift", {Sharing::kReferenceReading, in.reference.reading_id},
      std::move(drift));
}

// The quantity's own slope ∂f/∂λ: central differences, one-sided at the ends.
std::vector<double> SpectralSlope(const std::vector<double>& f, double step_nm) {
  const std::size_t n = f.size();
  std::vector<double> slope(n, 0.0);
  for (std::size_t b = 0; b < n && n > 1; ++b) {
    const std::size_t lo = b == 0 ? 0 : b - 1;
    const std::size_t hi = b + 1 == n ? b : b + 1;
    slope[b] = (f[hi] - f[lo]) / (static_cast<double>(hi - lo) * step_nm);
  }
  return slope;
}

void AddWavelengthAndStray(const BudgetInputs& in, const Evaluation& e, ReadingBudget& budget) {
  const SharedThrough instrument{Sharing::kInstrument, in.session_id};
  if (e.value.size() < 2) {
    budget.not_estimated.push_back("wavelength_scale: one band has no spectral slope");
  } else {
    std::vector<double> wavelength = SpectralSlope(e.value, in.grid.step_nm);
    for (double& w : wavelength) w *= in.terms.wavelength_nm;
    Add(budget, "wavelength_scale", instrument, std::move(wavelength));
  }
  std::vector<double> stray(e.value.size());
  for (std::size_t b = 0; b < stray.size(); ++b) {
    stray[b] = e.k[b] * (e.ratio[b] - 1.0) * in.terms.stray_light;
  }
  Add(budget, "stray_light", instrument, std::move(stray));
}

// pose_repeatability (independent) and pose_alignment_<axis> (the instrument's), through the
// gradient; the reference's share of β's alignment joins pose_alignment_beta. An axis whose
// gradient is unknown (empty) and whose pose is uncertain is named in not_estimated.
void AddPose(const BudgetInputs& in, const Evaluation& e, ReadingBudget& budget) {
  if (!in.pose_gradient.has_value()) {
    budget.not_estimated.push_back("pose: the quantity's gradient over the pose is not known");
    return;
  }
  const StageUncertainty& stage = in.terms.stage;
  const std::size_t n = e.value.size();
  const double tan_r = in.quantity == Quantity::kBrdf ? std::tan(in.theta_r_deg * kRadPerDeg) : 0;
  std::vector<double> repeat(n, 0.0);
  for (int a = 0; a < 4; ++a) {
    const std::vector<double>& g = (*in.pose_gradient)[a];
    const bool uncertain = stage.repeatability_deg[a] > 0 || stage.alignment_deg[a] > 0;
    if (g.empty()) {
      if (uncertain) {
        budget.not_estimated.push_back(std::string("pose_") + kAxisNames[a] +
                                       ": no neighbouring reading along " + kAxisNames[a] +
                                       " to estimate the gradient (zero for an isotropic sample "
                                       "on gamma)");
      }
      continue;
    }
    std::vector<double> align(n);
    for (std::size_t b = 0; b < n; ++b) {
      const double gr = g[b] * stage.repeatability_deg[a];
      repeat[b] = std::hypot(repeat[b], gr);
      const double ref = a == 1 ? e.value[b] * tan_r * kRadPerDeg : 0.0;
      align[b] = (g[b] + ref) * stage.alignment_deg[a];
    }
    if (stage.alignment_deg[a] > 0) {
      Add(budget, std::string("pose_alignment_") + kAxisNames[a],
          {Sharing::kInstrument, in.session_id}, std::move(align));
    }
  }
  Add(budget, "pose_repeatability", {}, std::move(repeat));
}

void Combine(ReadingBudget& budget) {
  const std::size_t n = budget.value.size();
  budget.combined.assign(n, 0.0);
  budget.independent.assign(n, 0.0);
  for (const Component& c : budget.components) {
    for (std::size_t b = 0; b < n; ++b) {
      const double u2 = c.contribution[b] * c.contribution[b];
      budget.combined[b] += u2;
      if (c.shared.kind == Sharing::kIndependent) budget.independent[b] += u2;
    }
  }
  for (double& u : budget.combined) u = std::sqrt(u);
  for (double& u : budget.independent) u = std::sqrt(u);
}

}  // namespace

const char* SharingName(Sharing sharing) {
  switch (sharing) {
    case Sharing::kIndependent:
      return "independent";
    case Sharing::kReferenceReading:
      return "reference_reading";
    case Sharing::kDarkReading:
      return "dark_reading";
    case Sharing::kWhiteStandard:
      return "white_standard";
    case Sharing::kInstrument:
      return "instrument";
  }
  return "unknown";
}

const Component* ReadingBudget::Find(const std::string& name) const {
  for (const Component& c : components) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

Result<ReadingBudget> EstimateReadingBudget(const BudgetInputs& in) {
  if (Status s = CheckInputs(in); !s.ok()) return s;
  Result<Evaluation> e = Evaluate(in);
  if (!e.ok()) return e.status();
  ReadingBudget budget;
  budget.quantity = in.quantity;
  budget.value = e->value;
  if (Status s = AddSignals(in, *e, budget); !s.ok()) return s;
  AddWhiteAndReferencePose(in, *e, budget);
  AddDrift(in, *e, budget);
  AddWavelengthAndStray(in, *e, budget);
  AddPose(in, *e, budget);
  Combine(budget);
  return budget;
}

}  // namespace brdf::uncertainty
