#include "core/fit/fit_report.h"

#include <charconv>
#include <cmath>

namespace brdf::fit {
namespace {

std::string Num(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// Three significant digits, for the comment block and the terminal.
std::string Short(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 4);
  return std::string(buf, r.ptr);
}

std::string ResidualText(const Residuals& r) {
  return "RMS " + Short(r.rms) + " sr⁻¹, relative RMS " + Short(r.relative_rms) + " (" +
         Short(100 * r.relative_rms) + " %), max |r| " + Short(r.max_abs) + " sr⁻¹";
}

std::string CookTorranceShared(const CookTorranceFit& ct) {
  if (ct.band.empty() || ct.sharing != ParameterSharing::kSharedAcrossBands) return "";
  return ": α = " + Short(ct.band.front().alpha) + " ± " + Short(ct.band_u.front().alpha) +
         ", F0 = " + Short(ct.band.front().f0) + " ± " + Short(ct.band_u.front().f0) + " (k = 1)";
}

// "χ²/dof = 1.02 (χ² = …, dof = …)" when weighted, else why there is none.
std::string ChiSquareText(const FitStatistics& s) {
  if (!s.weighted) return "χ²/dof: none (unweighted: not every reading carries an uncertainty)";
  return "χ²/dof = " + Short(s.chi2_per_dof) + " (" + WeightingText(s.weighting, s.shared_terms) +
         "; χ² = " + Short(s.chi2) + ", dof = " + Short(s.dof) + " = " + std::to_string(s.values) +
         " values − " + std::to_string(s.parameters) + " parameters)";
}

std::string WeightingLine(const FitReportInfo& info, const FitStatistics& s) {
  const std::string covariance =
      "; parameter uncertainties (_u, k = 1) from (JᵀV⁻¹J)⁻¹ at the optimum, not scaled by "
      "χ²/dof: χ²/dof ≫ 1 says the model does not describe the data within their uncertainty, "
      "and then the _u understate how uncertain the parameters are\n";
  if (s.weighting == Weighting::kGeneralised) {
    return "# weighting: " + WeightingText(s.weighting, s.shared_terms) +
           " (generalised least squares): per band, the values' covariance V = D + Σ b bᵀ, D the "
           "budgets' independent variances, one column b per shared source (white standard, "
           "reference reading, dark, instrument) with each reading's contribution "
           "(docs/uncertainty.md); χ² = Σ rᵀV⁻¹r" +
           (s.scale_terms > 0
                ? "; " + std::to_string(s.scale_terms) +
                      " of them a scale of every reading (the white standard's): left out of V, "
                      "where it cannot show in the residuals, and added to the _u of kd, ks and "
                      "the albedo"
                : std::string()) +
           covariance;
  }
  if (s.weighting == Weighting::kIndependent) {
    return "# weighting: " + WeightingText(s.weighting, s.shared_terms) +
           ": every value by 1/u², u its reading's combined standard uncertainty taken as "
           "independent of the others (docs/uncertainty.md)" +
           covariance;
  }
  return "# weighting: none, every value alike (" + std::to_string(info.with_uncertainty) + " of " +
         std::to_string(info.observations) +
         " readings carry an uncertainty; a weighted fit needs all); parameter uncertainties (_u, "
         "k = 1) from (JᵀJ)⁻¹ scaled by the residual variance Σ r² / dof, which assumes noise of "
         "one size everywhere; no χ²\n";
}

}  // namespace

std::string FitSummary(const LambertFit* lambert, const CookTorranceFit* ct) {
  std::string s;
  if (lambert != nullptr) {
    s += "Lambert: " + ResidualText(lambert->overall) + "; " + ChiSquareText(lambert->statistics) +
         "\n";
  }
  if (ct != nullptr) {
    s += "Cook-Torrance GGX (α, F0 " + std::string(ParameterSharingName(ct->sharing)) + ")" +
         CookTorranceShared(*ct) + ": " + ResidualText(ct->overall) +
         (ct->converged ? "" : " (search stopped at its evaluation cap)") + "; " +
         ChiSquareText(ct->statistics) + "\n";
  }
  return s;
}

std::string FitReportCsv(const FitReportInfo& info, const LambertFit* lambert,
                         const CookTorranceFit* ct) {
  std::string h;
  h += "# brdfd model evaluation: session " + std::to_string(info.session_id);
  if (!info.session_name.empty()) h += " \"" + info.session_name + "\"";
  h += "\n# data: BRDF f(λ) in sr⁻¹ of " + std::to_string(info.observations) +
       " sample readings (" + std::to_string(info.left_out) +
       " left out), fitted band by band by least squares on f\n";
  const FitStatistics none;
  h += WeightingLine(info, lambert != nullptr ? lambert->statistics
                           : ct != nullptr    ? ct->statistics
                                              : none);
  h += "# residuals: rms = √(Σ r² / n) in sr⁻¹; rel_rms = √(Σ r² / Σ f²) (0 = perfect, 1 = no "
       "better than f = 0)\n";
  if (lambert != nullptr) {
    h += "# lambert: f = ρ(λ) / π, ρ = π · mean f, weighted as the fit is (closed form); "
         "overall " +
         ResidualText(lambert->overall) + "; " + ChiSquareText(lambert->statistics) + "\n";
  }
  if (ct != nullptr) {
    h += "# cook_torrance: f = kd/π + ks · D · F · G1(ωi) G1(ωo) / (4 cos θi cos θo), GGX D with "
         "roughness α, Schlick F with F0, Smith G1; kd, ks per band; α and F0 " +
         std::string(ct->sharing == ParameterSharing::kPerBand ? "per band"
                                                               : "shared by all bands") +
         CookTorranceShared(*ct) + "; Nelder-Mead over (α, F0), (kd, ks) solved exactly; " +
         std::to_string(ct->evaluations) + " evaluations" +
         (ct->converged ? "" : ", stopped at the evaluation cap") + "\n";
    h += "# cook_torrance overall " + ResidualText(ct->overall) + "; " +
         ChiSquareText(ct->statistics) + "\n";
    if (!ct->statistics.note.empty()) h += "# cook_torrance: " + ct->statistics.note + "\n";
  }
  if (lambert == nullptr && ct == nullptr) return h;
  h += "wavelength_nm";
  if (lambert != nullptr) h += ",lambert_albedo,lambert_albedo_u,lambert_rms,lambert_rel_rms";
  if (ct != nullptr) {
    h += ",ct_kd,ct_kd_u,ct_ks,ct_ks_u,ct_alpha,ct_alpha_u,ct_f0,ct_f0_u,ct_rms,ct_rel_rms";
  }
  h += '\n';
  const WavelengthGrid grid = lambert != nullptr ? lambert->grid : ct->grid;
  for (std::size_t b = 0; b < grid.count; ++b) {
    h += Num(grid.at(b));
    if (lambert != nullptr) {
      h += ',' + Num(lambert->albedo[b]) + ',' + Num(lambert->albedo_u[b]) + ',' +
           Num(lambert->band_residuals[b].rms) + ',' + Num(lambert->band_residuals[b].relative_rms);
    }
    if (ct != nullptr) {
      const CookTorranceParams& p = ct->band[b];
      const CookTorranceParams& u = ct->band_u[b];
      h += ',' + Num(p.kd) + ',' + Num(u.kd) + ',' + Num(p.ks) + ',' + Num(u.ks) + ',' +
           Num(p.alpha) + ',' + Num(u.alpha) + ',' + Num(p.f0) + ',' + Num(u.f0) + ',' +
           Num(ct->band_residuals[b].rms) + ',' + Num(ct->band_residuals[b].relative_rms);
    }
    h += '\n';
  }
  return h;
}

}  // namespace brdf::fit
