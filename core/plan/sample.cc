#include "core/plan/sample.h"

#include <cmath>
#include <string>

namespace brdf::plan {
namespace {

void CheckText(const std::string& path, const std::string& text, std::size_t max,
               ProblemSink& sink) {
  if (text.size() > max) {
    sink.Add(path, "is " + std::to_string(text.size()) + " bytes long; give at most " +
                       std::to_string(max));
  }
}

bool IsReflectance(double v) {
  return std::isfinite(v) && v > 0 && v <= 1;
}

}  // namespace

void CheckSample(const v1::Sample& sample, ProblemSink& sink) {
  CheckText("sample.id", sample.id(), kMaxSampleTextLength, sink);
  CheckText("sample.name", sample.name(), kMaxSampleTextLength, sink);
  CheckText("sample.material", sample.material(), kMaxSampleTextLength, sink);
  CheckText("sample.whiteStandardId", sample.white_standard_id(), kMaxSampleTextLength, sink);
  CheckText("sample.description", sample.description(), kMaxSampleDescriptionLength, sink);
  if (sample.tags_size() > kMaxSampleTags) {
    sink.Add("sample.tags", "has " + std::to_string(sample.tags_size()) + " tags; give at most " +
                                std::to_string(kMaxSampleTags));
  }
  for (int i = 0; i < sample.tags_size() && i < kMaxSampleTags; ++i) {
    const std::string path = "sample.tags[" + std::to_string(i) + "]";
    if (sample.tags(i).empty()) sink.Add(path, "is empty; remove it or give a word");
    CheckText(path, sample.tags(i), kMaxSampleTextLength, sink);
  }
  if (sample.has_white_reflectance() && !IsReflectance(sample.white_reflectance())) {
    sink.Add("sample.whiteReflectance",
             "must be in (0, 1] (got " + std::to_string(sample.white_reflectance()) +
                 "); give the white standard's certified reflectance, e.g. 0.99");
  }
  if (sample.has_white_reflectance_uncertainty()) {
    const double u = sample.white_reflectance_uncertainty();
    if (!std::isfinite(u) || u < 0 || u > 0.5) {
      sink.Add("sample.whiteReflectanceUncertainty",
               "must be in [0, 0.5] (got " + std::to_string(u) +
                   "); give the standard uncertainty (k = 1) of ρw, e.g. 0.005 for a certificate's "
                   "±0.01 at k = 2");
    }
  }
  if (!sample.has_white_reflectance_spectrum()) return;
  const v1::WhiteReflectanceSpectrum& s = sample.white_reflectance_spectrum();
  const std::string path = "sample.whiteReflectanceSpectrum";
  if (!std::isfinite(s.start_nm()) || s.start_nm() <= 0) {
    sink.Add(path + ".startNm",
             "must be a wavelength > 0 nm (got " + std::to_string(s.start_nm()) + ")");
  }
  if (!std::isfinite(s.step_nm()) || s.step_nm() <= 0) {
    sink.Add(path + ".stepNm", "must be > 0 nm (got " + std::to_string(s.step_nm()) + ")");
  }
  if (s.values_size() < 2) {
    sink.Add(path + ".values", "has " + std::to_string(s.values_size()) +
                                   " value(s); give ρw at 2 or more wavelengths");
  }
  for (int i = 0; i < s.values_size(); ++i) {
    if (!IsReflectance(s.values(i))) {
      sink.AddOnce(path + ".values", "value " + std::to_string(i) + " is " +
                                         std::to_string(s.values(i)) + "; each must be in (0, 1]");
    }
  }
}

std::optional<Spectrum> WhiteReflectanceSpectrumOf(const v1::Plan& plan) {
  if (!plan.has_sample() || !plan.sample().has_white_reflectance_spectrum()) return std::nullopt;
  const v1::WhiteReflectanceSpectrum& s = plan.sample().white_reflectance_spectrum();
  Spectrum out;
  out.grid = WavelengthGrid{s.start_nm(), s.step_nm(), static_cast<std::size_t>(s.values_size())};
  out.values.assign(s.values().begin(), s.values().end());
  return out;
}

std::optional<double> WhiteReflectanceOf(const v1::Plan& plan) {
  if (!plan.has_sample() || plan.sample().has_white_reflectance_spectrum() ||
      !plan.sample().has_white_reflectance()) {
    return std::nullopt;
  }
  return plan.sample().white_reflectance();
}

std::optional<double> WhiteReflectanceUncertaintyOf(const v1::Plan& plan) {
  if (!plan.has_sample() || !plan.sample().has_white_reflectance_uncertainty()) {
    return std::nullopt;
  }
  return plan.sample().white_reflectance_uncertainty();
}

}  // namespace brdf::plan
