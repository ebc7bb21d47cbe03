#include "storage/uncertainty_columns.h"

#include <cmath>
#include <cstdlib>
#include <span>
#include <sstream>

#include "storage/spectrum_blob.h"

namespace brdf::storage {
namespace {

using uncertainty::Component;
using uncertainty::ReadingBudget;
using uncertainty::Sharing;

constexpr Sharing kSharings[] = {Sharing::kIndependent, Sharing::kReferenceReading,
                                 Sharing::kDarkReading, Sharing::kWhiteStandard,
                                 Sharing::kInstrument};

Status CheckBands(const std::vector<double>& v, std::size_t bands, const std::string& what,
                  bool non_negative) {
  if (v.size() != bands) {
    return InvalidArgument("the uncertainty's " + what + " has " + std::to_string(v.size()) +
                           " values; the reading has " + std::to_string(bands) + " bands");
  }
  for (double x : v) {
    if (!std::isfinite(x) || (non_negative && x < 0)) {
      return InvalidArgument("the uncertainty's " + what + " has a " +
                             (non_negative ? "negative or " : "") + "non-finite value");
    }
  }
  return Status::Ok();
}

Status CheckText(const std::string& text, const std::string& what) {
  if (text.empty() || text.find_first_of("\t\r\n") != std::string::npos) {
    return InvalidArgument("the uncertainty's " + what + " '" + text +
                           "' is empty or holds a tab or line break");
  }
  return Status::Ok();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

Result<Sharing> ParseSharing(const std::string& word) {
  for (Sharing s : kSharings) {
    if (word == uncertainty::SharingName(s)) return s;
  }
  return InvalidArgument("unknown sharing '" + word + "'");
}

// One line of the components column: "name<TAB>sharing<TAB>id".
Result<Component> ParseComponentLine(const std::string& line) {
  const std::size_t a = line.find('\t');
  const std::size_t b = a == std::string::npos ? a : line.find('\t', a + 1);
  if (b == std::string::npos)
    return InvalidArgument("component line '" + line + "' is not name, sharing, id");
  Component c;
  c.name = line.substr(0, a);
  BRDF_ASSIGN_OR_RETURN(c.shared.kind, ParseSharing(line.substr(a + 1, b - a - 1)));
  const std::string id = line.substr(b + 1);
  char* end = nullptr;
  c.shared.id = std::strtoll(id.c_str(), &end, 10);
  if (id.empty() || *end != '\0')
    return InvalidArgument("component line '" + line + "' has a bad id");
  return c;
}

}  // namespace

Result<UncertaintyColumns> EncodeUncertainty(const ReadingBudget& budget, std::size_t bands) {
  if (budget.quantity != Quantity::kBrdf && budget.quantity != Quantity::kReflectance) {
    return InvalidArgument("a reading's uncertainty is of its BRDF or reflectance, not its " +
                           std::string(QuantityName(budget.quantity)));
  }
  BRDF_RETURN_IF_ERROR(CheckBands(budget.value, bands, "value", false));
  BRDF_RETURN_IF_ERROR(CheckBands(budget.combined, bands, "combined", true));
  BRDF_RETURN_IF_ERROR(CheckBands(budget.independent, bands, "independent part", true));
  UncertaintyColumns out;
  out.quantity = QuantityName(budget.quantity);
  out.value = EncodeSpectrum(budget.value);
  out.combined = EncodeSpectrum(budget.combined);
  out.independent = EncodeSpectrum(budget.independent);
  std::vector<double> all;
  for (const Component& c : budget.components) {
    BRDF_RETURN_IF_ERROR(CheckText(c.name, "component name"));
    BRDF_RETURN_IF_ERROR(CheckBands(c.contribution, bands, "component " + c.name, false));
    out.components += c.name + "\t" + uncertainty::SharingName(c.shared.kind) + "\t" +
                      std::to_string(c.shared.id) + "\n";
    all.insert(all.end(), c.contribution.begin(), c.contribution.end());
  }
  out.contributions = EncodeSpectrum(all);
  for (const std::string& why : budget.not_estimated) {
    BRDF_RETURN_IF_ERROR(CheckText(why, "reason"));
    out.not_estimated += why + "\n";
  }
  return out;
}

Result<ReadingBudget> DecodeUncertainty(const UncertaintyColumns& columns, std::size_t bands) {
  ReadingBudget budget;
  Result<Quantity> quantity = ParseQuantity(columns.quantity);
  if (!quantity.ok()) return quantity.status().WithContext("its quantity");
  budget.quantity = *quantity;
  Result<std::vector<double>> value = DecodeSpectrum(columns.value, bands);
  if (!value.ok()) return value.status().WithContext("its value");
  budget.value = std::move(*value);
  Result<std::vector<double>> combined = DecodeSpectrum(columns.combined, bands);
  if (!combined.ok()) return combined.status().WithContext("its combined uncertainty");
  budget.combined = std::move(*combined);
  Result<std::vector<double>> independent = DecodeSpectrum(columns.independent, bands);
  if (!independent.ok()) return independent.status().WithContext("its independent part");
  budget.independent = std::move(*independent);
  const std::vector<std::string> lines = Lines(columns.components);
  Result<std::vector<double>> all = DecodeSpectrum(columns.contributions, lines.size() * bands);
  if (!all.ok()) return all.status().WithContext("its contributions");
  for (std::size_t i = 0; i < lines.size(); ++i) {
    Result<Component> c = ParseComponentLine(lines[i]);
    if (!c.ok()) return c.status().WithContext("its components");
    const auto first = all->begin() + static_cast<std::ptrdiff_t>(i * bands);
    c->contribution.assign(first, first + static_cast<std::ptrdiff_t>(bands));
    budget.components.push_back(std::move(*c));
  }
  budget.not_estimated = Lines(columns.not_estimated);
  return budget;
}

}  // namespace brdf::storage
