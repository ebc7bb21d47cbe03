#include "core/material/material_reader.h"

#include <memory>
#include <utility>
#include <vector>

#include "core/material/diffuse_lobes.h"
#include "core/material/glossy_lobes.h"
#include "core/material/spectral_reader.h"
#include "core/toml/table_reader.h"

namespace brdf::material {
namespace {

using toml_keys::Problems;
using toml_keys::TableReader;

using LobePtr = std::shared_ptr<const Lobe>;

constexpr ValueRange kFraction{0, 1};      // albedos, F0
constexpr ValueRange kWeight{0, 100};      // a lobe's scale factor
constexpr ValueRange kIndex{0.01, 100};    // a conductor's n
constexpr ValueRange kExtinction{0, 100};  // a conductor's k
constexpr double kMinRoughness = 1e-3, kMaxRoughness = 2;
constexpr double kMaxExponent = 1e6;

// A required spectral parameter: noted as missing when absent.
bool RequireSpectral(TableReader& t, Problems& problems, std::string_view key, ValueRange range,
                     SpectralValue& out, std::string_view hint = "") {
  if (!t.Require(key, hint)) return false;
  return ReadSpectral(t, problems, key, range, out);
}

// The weight of a glossy lobe: 1 when absent.
bool OptionalWeight(TableReader& t, Problems& problems, SpectralValue& weight) {
  weight = SpectralValue::Constant(1);
  return t.Node("weight") == nullptr || ReadSpectral(t, problems, "weight", kWeight, weight);
}

// One value `key`, or a pair `key`_x and `key`_y (anisotropic); both forms are not allowed.
bool ReadPair(TableReader& t, std::string_view key, double lo, double hi, bool lo_open, double& x,
              double& y) {
  const std::string kx = std::string(key) + "_x", ky = std::string(key) + "_y";
  const bool one = t.Node(key) != nullptr;
  const bool split = t.Node(kx) != nullptr || t.Node(ky) != nullptr;
  if (one && split) {
    t.Issue(key, "give either " + std::string(key) + " or " + kx + " and " + ky + ", not both");
    return false;
  }
  if (one) {
    if (!t.Double(key, x, lo, hi, lo_open)) return false;
    y = x;
    return true;
  }
  if (!split) {
    t.Require(key, "or " + kx + " and " + ky);
    return false;
  }
  return t.Require(kx) && t.Double(kx, x, lo, hi, lo_open) && t.Require(ky) &&
         t.Double(ky, y, lo, hi, lo_open);
}

bool ReadFresnel(TableReader& t, Problems& problems, Fresnel& out) {
  std::size_t kind = 0;
  if (!t.Require("fresnel",
                 "one of \"schlick\" (with f0), \"conductor\" (with n and k), "
                 "\"none\"") ||
      !t.OneOf("fresnel", kind, {"none", "schlick", "conductor"})) {
    t.Allow({"f0", "n", "k"});
    return false;
  }
  if (kind == 0) return true;
  if (kind == 1) {
    SpectralValue f0;
    if (!RequireSpectral(t, problems, "f0", kFraction, f0, "fresnel = \"schlick\" needs f0")) {
      return false;
    }
    out = Fresnel::Schlick(std::move(f0));
    return true;
  }
  SpectralValue n, k;
  const bool n_ok =
      RequireSpectral(t, problems, "n", kIndex, n, "fresnel = \"conductor\" needs n (and k)");
  const bool k_ok = t.Node("k") == nullptr || ReadSpectral(t, problems, "k", kExtinction, k);
  if (!n_ok || !k_ok) return false;
  out = Fresnel::Conductor(std::move(n), std::move(k));
  return true;
}

LobePtr ReadLambert(TableReader& t, Problems& problems) {
  SpectralValue albedo;
  if (!RequireSpectral(t, problems, "albedo", kFraction, albedo)) return nullptr;
  return std::make_shared<LambertLobe>(std::move(albedo));
}

LobePtr ReadOrenNayar(TableReader& t, Problems& problems) {
  SpectralValue albedo;
  double sigma = 0;
  const bool albedo_ok = RequireSpectral(t, problems, "albedo", kFraction, albedo);
  const bool sigma_ok = t.Require("sigma_deg", "the facets' slope spread, degrees") &&
                        t.Double("sigma_deg", sigma, 0, 90);
  if (!albedo_ok || !sigma_ok) return nullptr;
  return std::make_shared<OrenNayarLobe>(std::move(albedo), sigma);
}

LobePtr ReadMicrofacet(TableReader& t, Problems& problems, FacetSlopes slopes) {
  Roughness alpha;
  Fresnel fresnel;
  SpectralValue weight;
  const bool alpha_ok =
      ReadPair(t, "roughness", kMinRoughness, kMaxRoughness, false, alpha.x, alpha.y);
  const bool fresnel_ok = ReadFresnel(t, problems, fresnel);
  const bool weight_ok = OptionalWeight(t, problems, weight);
  if (!alpha_ok || !fresnel_ok || !weight_ok) return nullptr;
  return std::make_shared<MicrofacetLobe>(slopes, alpha, std::move(fresnel), std::move(weight));
}

LobePtr ReadBlinnPhong(TableReader& t, Problems& problems) {
  SpectralValue weight;
  double ex = 0, ey = 0;
  const bool exponent_ok = ReadPair(t, "exponent", 0, kMaxExponent, false, ex, ey);
  const bool weight_ok = OptionalWeight(t, problems, weight);
  if (!exponent_ok || !weight_ok) return nullptr;
  return std::make_shared<BlinnPhongLobe>(std::move(weight), ex, ey);
}

LobePtr ReadRetro(TableReader& t, Problems& problems) {
  SpectralValue weight;
  double exponent = 0;
  const bool exponent_ok = t.Require("exponent") && t.Double("exponent", exponent, 0, kMaxExponent);
  const bool weight_ok = OptionalWeight(t, problems, weight);
  if (!exponent_ok || !weight_ok) return nullptr;
  return std::make_shared<RetroLobe>(std::move(weight), exponent);
}

LobePtr ReadLobe(TableReader& t, Problems& problems) {
  std::size_t type = 0;
  if (!t.Require("type") ||
      !t.OneOf("type", type,
               {"lambert", "oren_nayar", "ggx", "beckmann", "blinn_phong", "retro"})) {
    // Without a type its other keys cannot be judged: report the type alone.
    if (t.table() != nullptr) {
      for (const auto& [key, node] : *t.table()) t.Node(key.str());
    }
    return nullptr;
  }
  switch (type) {
    case 0:
      return ReadLambert(t, problems);
    case 1:
      return ReadOrenNayar(t, problems);
    case 2:
      return ReadMicrofacet(t, problems, FacetSlopes::kGgx);
    case 3:
      return ReadMicrofacet(t, problems, FacetSlopes::kBeckmann);
    case 4:
      return ReadBlinnPhong(t, problems);
    default:
      return ReadRetro(t, problems);
  }
}

}  // namespace

Result<Material> ReadMaterial(std::string_view toml_text, const std::string& source,
                              const std::string& default_name) {
  Problems problems("material file " + source, StatusCode::kInvalidArgument,
                    "fix the file (docs/materials.md describes every key; deploy/materials/ "
                    "holds examples)");
  BRDF_ASSIGN_OR_RETURN(const toml::table doc, problems.Parse(toml_text, source));
  TableReader root(problems, &doc);
  std::string name = default_name;
  root.String("name", name);
  std::string description;
  root.String("description", description, toml_keys::Empty::kAllowed);
  std::vector<LobePtr> lobes;
  if (root.Require("lobe", "a material needs at least one [[lobe]] table")) {
    root.ArrayOfTables("lobe", "a type and its parameters", [&](TableReader& t, std::size_t) {
      if (LobePtr lobe = ReadLobe(t, problems)) lobes.push_back(std::move(lobe));
      t.Finish();
    });
  }
  root.Finish();
  BRDF_RETURN_IF_ERROR(problems.status());
  if (lobes.empty()) {
    return InvalidArgument("material file " + source +
                           ": no lobes; add at least one [[lobe]] table (docs/materials.md)");
  }
  return Material(std::move(name), std::move(lobes));
}

}  // namespace brdf::material
