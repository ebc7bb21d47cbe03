#include "core/readings/quantity.h"

namespace brdf {

const char* QuantityName(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "radiance";
    case Quantity::kReflectance:
      return "reflectance";
    case Quantity::kBrdf:
      return "brdf";
  }
  return "unknown";
}

const char* QuantityUnit(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "W·m⁻²·sr⁻¹·nm⁻¹";
    case Quantity::kReflectance:
      return "1 (unitless)";
    case Quantity::kBrdf:
      return "sr⁻¹";
  }
  return "";
}

std::string QuantityDefinition(Quantity q) {
  switch (q) {
    case Quantity::kRadiance:
      return "spectral radiance I(λ) of the sample, minus the dark reading D(λ) it names (if any), "
             "in W·m⁻²·sr⁻¹·nm⁻¹";
    case Quantity::kReflectance:
      return "reflectance R(λ) = (I(λ) − D(λ)) / (I0(λ) − D(λ)): the sample's radiance over the "
             "white standard's (the reference reading it names), dark subtracted from both when "
             "measured; unitless";
    case Quantity::kBrdf:
      return "BRDF f(λ) = R(λ) · ρw / π · cos θi,ref / cos θi in sr⁻¹, with R = (I − D) / (I0 − "
             "D), "
             "ρw the white standard's reflectance and θi,ref the incidence of the reference "
             "reading";
  }
  return "";
}

Result<Quantity> ParseQuantity(std::string_view name) {
  if (name == "radiance") return Quantity::kRadiance;
  if (name == "reflectance") return Quantity::kReflectance;
  if (name == "brdf") return Quantity::kBrdf;
  return InvalidArgument("unknown quantity '" + std::string(name) +
                         "': use radiance, reflectance or brdf");
}

}  // namespace brdf
