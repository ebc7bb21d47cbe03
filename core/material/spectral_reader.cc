#include "core/material/spectral_reader.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace brdf::material {
namespace {

using toml_keys::Problems;
using toml_keys::TableReader;

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string RangeText(const ValueRange& r) {
  return "[" + Num(r.lo) + ", " + Num(r.hi) + "]";
}

bool NumberOf(const toml::node& n, double& out) {
  if (n.is_integer()) {
    out = static_cast<double>(n.as_integer()->get());
    return true;
  }
  if (n.is_floating_point()) {
    out = n.as_floating_point()->get();
    return std::isfinite(out);
  }
  return false;
}

// One [nm, value] element of a table, at `path` ("lobe[0].albedo[3]").
bool ReadPoint(const toml::node& element, const std::string& path, ValueRange range,
               Problems& problems, std::pair<double, double>& point) {
  const toml::array* pair = element.as_array();
  if (pair == nullptr || pair->size() != 2 || !NumberOf(*pair->get(0), point.first) ||
      !NumberOf(*pair->get(1), point.second)) {
    problems.Add(element.source(), path, "must be a pair [nm, value] of finite numbers");
    return false;
  }
  if (!(point.first > 0)) {
    problems.Add(element.source(), path, "wavelength " + Num(point.first) + " nm is not > 0");
    return false;
  }
  if (point.second < range.lo || point.second > range.hi) {
    problems.Add(element.source(), path,
                 "value " + Num(point.second) + " at " + Num(point.first) + " nm is outside " +
                     RangeText(range));
    return false;
  }
  return true;
}

bool ReadTable(const toml::array& list, const std::string& path, ValueRange range,
               Problems& problems, SpectralValue& out) {
  if (list.empty()) {
    problems.Add(list.source(), path, "an empty table; give [nm, value] pairs or a number");
    return false;
  }
  std::vector<std::pair<double, double>> points;
  bool ok = true;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string at = path + "[" + std::to_string(i) + "]";
    std::pair<double, double> p;
    if (!ReadPoint(*list.get(i), at, range, problems, p)) {
      ok = false;
      continue;
    }
    if (!points.empty() && !(p.first > points.back().first)) {
      problems.Add(list.get(i)->source(), at,
                   "wavelengths must increase: " + Num(p.first) + " nm follows " +
                       Num(points.back().first) + " nm");
      ok = false;
    }
    points.push_back(p);
  }
  if (ok) out = SpectralValue::Table(std::move(points));
  return ok;
}

bool ReadBump(const toml::table& table, const std::string& path, ValueRange range,
              Problems& problems, SpectralValue& out) {
  TableReader bump(problems, &table, path);
  double base = 0, amplitude = 0, center = 0, width = 0;
  const bool base_ok = bump.Node("base") == nullptr || bump.Double("base", base);
  const bool amplitude_ok = bump.Require("amplitude") && bump.Double("amplitude", amplitude);
  const bool center_ok =
      bump.Require("center_nm") && bump.Double("center_nm", center, 0, 1e5, true);
  const bool width_ok = bump.Require("width_nm") && bump.Double("width_nm", width, 0, 1e5, true);
  bump.Finish();
  if (!base_ok || !amplitude_ok || !center_ok || !width_ok) return false;
  const SpectralValue v = SpectralValue::Bump(base, amplitude, center, width);
  if (v.Min() < range.lo || v.Max() > range.hi) {
    problems.Add(table.source(), path,
                 "base + amplitude spans " + Num(v.Min()) + " … " + Num(v.Max()) + ", outside " +
                     RangeText(range));
    return false;
  }
  out = v;
  return true;
}

}  // namespace

bool ReadSpectral(TableReader& table, Problems& problems, std::string_view key, ValueRange range,
                  SpectralValue& out) {
  const toml::node* n = table.Node(key);
  if (n == nullptr) return false;
  const std::string path = table.KeyPath(key);
  double v = 0;
  if (NumberOf(*n, v)) {
    if (v < range.lo || v > range.hi) {
      table.Issue(key, Num(v) + " is outside " + RangeText(range));
      return false;
    }
    out = SpectralValue::Constant(v);
    return true;
  }
  if (const toml::array* list = n->as_array()) return ReadTable(*list, path, range, problems, out);
  if (const toml::table* bump = n->as_table()) return ReadBump(*bump, path, range, problems, out);
  table.Issue(key, std::string("must be a number, a table of [nm, value] pairs or a bump "
                               "{ base, amplitude, center_nm, width_nm }, not ") +
                       toml_keys::TypeName(n->type()));
  return false;
}

}  // namespace brdf::material
