#include "tools/brdfctl/output/uncertainty_text.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tools/brdfctl/output/text_format.h"

namespace brdf::ctl {
namespace {

std::string KText(double k) {
  return "k=" + Num(k, 3);
}

}  // namespace

std::string UncertaintySummary(const v1::Reading& reading, double k) {
  if (reading.kind() != v1::READING_KIND_SAMPLE) return "";
  if (!reading.has_uncertainty()) return "± not estimated";
  const v1::ReadingUncertainty& u = reading.uncertainty();
  std::vector<double> relative;
  for (int b = 0; b < u.combined_size() && b < u.value_size(); ++b) {
    if (u.value(b) != 0 && std::isfinite(u.value(b))) {
      relative.push_back(100.0 * k * u.combined(b) / std::abs(u.value(b)));
    }
  }
  const std::string name = QuantityName(u.quantity());
  if (relative.empty()) return name + " ± (no band with a value)";
  std::sort(relative.begin(), relative.end());
  const std::size_t n = relative.size();
  const double median = n % 2 == 1 ? relative[n / 2] : (relative[n / 2 - 1] + relative[n / 2]) / 2;
  return name + " ±" + Num(median, 2) + " % (" + KText(k) + "; " + Num(relative.front(), 2) + "–" +
         Num(relative.back(), 2) + " % over bands)";
}

std::string UncertaintyBand(const v1::ReadingUncertainty& u, int band, double k) {
  if (band < 0 || band >= u.value_size() || band >= u.combined_size()) return "";
  return QuantityName(u.quantity()) + " " + Num(u.value(band), 6) + " ± " +
         Num(k * u.combined(band), 3) + " " + QuantityUnit(u.quantity()) + " (" + KText(k) + ")";
}

}  // namespace brdf::ctl
