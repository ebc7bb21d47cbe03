#include "core/export/rgl/reader.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

namespace brdf::exports {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

std::uint64_t ReadLe(std::string_view b, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) {
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(b[at + i])) << (8 * i);
  }
  return v;
}

float ThetaToU(float theta) {
  return std::sqrt(theta * (2 / kPi));
}
float PhiToU(float phi) {
  return (phi + kPi) / (2 * kPi);
}

}  // namespace

Result<std::map<std::string, RglTensor>> ParseTensorFile(std::string_view b) {
  if (b.size() < 18 || std::memcmp(b.data(), "tensor_file\0", 12) != 0) {
    return InvalidArgument("not a tensor_file: the first 12 bytes are not \"tensor_file\\0\"");
  }
  if (b[12] != 1 || b[13] != 0) return InvalidArgument("tensor_file: version is not 1.0");
  const std::uint64_t count = ReadLe(b, 14, 4);
  std::size_t at = 18;
  std::map<std::string, RglTensor> fields;
  for (std::uint64_t i = 0; i < count; ++i) {
    if (at + 2 > b.size()) return InvalidArgument("tensor_file: field table cut short");
    const std::size_t len = ReadLe(b, at, 2);
    if (at + 2 + len + 11 > b.size()) return InvalidArgument("tensor_file: field table cut short");
    const std::string name(b.substr(at + 2, len));
    at += 2 + len;
    RglTensor t;
    const std::size_t ndim = ReadLe(b, at, 2);
    t.dtype = static_cast<std::uint8_t>(b[at + 2]);
    const std::uint64_t offset = ReadLe(b, at + 3, 8);
    at += 11;
    if (at + 8 * ndim > b.size()) return InvalidArgument("tensor_file: field table cut short");
    std::uint64_t n = 1;
    for (std::size_t d = 0; d < ndim; ++d) {
      t.shape.push_back(ReadLe(b, at + 8 * d, 8));
      n *= t.shape.back();
    }
    at += 8 * ndim;
    const std::size_t size = t.dtype == 1 ? 1 : t.dtype == 10 ? 4 : 0;
    if (size == 0) {
      return InvalidArgument("tensor_file: field '" + name + "' has dtype " +
                             std::to_string(t.dtype) + "; only uint8 (1) and float32 (10) read");
    }
    if (offset > b.size() || n * size > b.size() - offset) {
      return InvalidArgument("tensor_file: field '" + name + "' runs past the end of the file");
    }
    if (size == 1) {
      t.u8.assign(b.begin() + static_cast<std::ptrdiff_t>(offset),
                  b.begin() + static_cast<std::ptrdiff_t>(offset + n));
    } else {
      t.f32.resize(n);
      for (std::uint64_t k = 0; k < n; ++k) {
        t.f32[k] = std::bit_cast<float>(static_cast<std::uint32_t>(ReadLe(b, offset + 4 * k, 4)));
      }
    }
    fields[name] = std::move(t);
  }
  return fields;
}

Result<RglMaterial> RglMaterial::Parse(std::string_view bytes) {
  BRDF_ASSIGN_OR_RETURN(auto parsed, ParseTensorFile(bytes));
  std::map<std::string, RglTensor>& f = parsed;
  RglMaterial m;
  m.rgb_ = f.count("rgb") > 0 && f.count("spectra") == 0;
  const std::string values_name = m.rgb_ ? "rgb" : "spectra";
  for (const char* name :
       {"description", "jacobian", "theta_i", "phi_i", "ndf", "sigma", "vndf", "luminance"}) {
    if (f.count(name) == 0)
      return InvalidArgument(std::string("RGL file: no field '") + name + "'");
  }
  if (f.count(values_name) == 0 || (!m.rgb_ && f.count("wavelengths") == 0)) {
    return InvalidArgument("RGL file: needs 'wavelengths' and 'spectra', or 'rgb'");
  }
  const RglTensor &ti = f["theta_i"], &pi = f["phi_i"], &ndf = f["ndf"], &sigma = f["sigma"],
                  &vndf = f["vndf"], &lum = f["luminance"], &val = f[values_name],
                  &jac = f["jacobian"], &desc = f["description"];
  const bool ok =
      desc.dtype == 1 && desc.shape.size() == 1 && jac.dtype == 1 &&
      jac.shape == std::vector<std::uint64_t>{1} && ti.dtype == 10 && ti.shape.size() == 1 &&
      pi.dtype == 10 && pi.shape.size() == 1 && ndf.dtype == 10 && ndf.shape.size() == 2 &&
      sigma.dtype == 10 && sigma.shape.size() == 2 && vndf.dtype == 10 && vndf.shape.size() == 4 &&
      vndf.shape[0] == pi.shape[0] && vndf.shape[1] == ti.shape[0] && lum.dtype == 10 &&
      lum.shape.size() == 4 && lum.shape[0] == pi.shape[0] && lum.shape[1] == ti.shape[0] &&
      lum.shape[2] == lum.shape[3] && val.dtype == 10 && val.shape.size() == 5 &&
      val.shape[0] == pi.shape[0] && val.shape[1] == ti.shape[0] && val.shape[3] == val.shape[4] &&
      lum.shape[2] == val.shape[3] && lum.shape[3] == val.shape[4];
  if (!ok) return InvalidArgument("RGL file: fields with the wrong dtype or shape");
  if (m.rgb_) {
    if (val.shape[2] != 3) return InvalidArgument("RGL file: 'rgb' needs 3 channels");
  } else {
    const RglTensor& wl = f["wavelengths"];
    if (wl.dtype != 10 || wl.shape.size() != 1 || wl.shape[0] != val.shape[2]) {
      return InvalidArgument("RGL file: 'wavelengths' does not match 'spectra'");
    }
    m.wavelengths_ = wl.f32;
  }
  if (pi.shape[0] > 2) return InvalidArgument("RGL file: anisotropic files are not read here");
  m.channels_ = val.shape[2];
  m.jacobian_ = jac.u8[0] != 0;
  m.description_.assign(desc.u8.begin(), desc.u8.end());
  m.ndf_ = Warp2D(ndf.shape[1], ndf.shape[0], ndf.f32.data(), {}, false, false);
  m.sigma_ = Warp2D(sigma.shape[1], sigma.shape[0], sigma.f32.data(), {}, false, false);
  m.vndf_ = Warp2D(vndf.shape[3], vndf.shape[2], vndf.f32.data(), {pi.f32, ti.f32}, true, true);
  std::vector<float> channel(m.channels_);
  for (std::size_t c = 0; c < m.channels_; ++c) {
    channel[c] = m.rgb_ ? static_cast<float>(c) : m.wavelengths_[c];
  }
  m.values_ =
      Warp2D(val.shape[4], val.shape[3], val.f32.data(), {pi.f32, ti.f32, channel}, false, false);
  return m;
}

std::vector<double> RglMaterial::BrdfCosine(const Directions& d) const {
  std::vector<double> out(channels_, 0.0);
  const float deg = kPi / 180;
  const float ti = static_cast<float>(d.theta_i) * deg, pi = static_cast<float>(d.phi_i) * deg;
  const float to = static_cast<float>(d.theta_o) * deg, po = static_cast<float>(d.phi_o) * deg;
  const float wi[3] = {std::sin(ti) * std::cos(pi), std::sin(ti) * std::sin(pi), std::cos(ti)};
  const float wo[3] = {std::sin(to) * std::cos(po), std::sin(to) * std::sin(po), std::cos(to)};
  if (wi[2] <= 0 || wo[2] <= 0) return out;
  float m[3] = {wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]};
  const float len = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  if (len == 0) return out;
  for (float& v : m) v /= len;
  const float theta_i = std::acos(std::clamp(wi[2], -1.0f, 1.0f));
  const float phi_i = std::atan2(wi[1], wi[0]);
  const float theta_m = std::acos(std::clamp(m[2], -1.0f, 1.0f));
  const float phi_m = std::atan2(m[1], m[0]);
  const float ui[2] = {ThetaToU(theta_i), PhiToU(phi_i)};
  float um[2] = {ThetaToU(theta_m), PhiToU(isotropic_ ? phi_m - phi_i : phi_m)};
  um[1] -= std::floor(um[1]);
  const float params[2] = {phi_i, theta_i};
  const WarpPoint s = vndf_.Invert(um[0], um[1], params);
  const float scale =
      jacobian_ ? ndf_.Eval(um[0], um[1], params) / (4 * sigma_.Eval(ui[0], ui[1], params)) : 1;
  for (std::size_t c = 0; c < channels_; ++c) {
    const float p3[3] = {phi_i, theta_i, rgb_ ? static_cast<float>(c) : wavelengths_[c]};
    out[c] = static_cast<double>(values_.Eval(s.x, s.y, p3)) * scale;
  }
  return out;
}

std::vector<double> RglMaterial::Brdf(const Directions& d) const {
  std::vector<double> out = BrdfCosine(d);
  const double c = std::cos(d.theta_o * std::numbers::pi / 180);
  for (double& v : out) v = c > 0 ? v / c : 0;
  return out;
}

}  // namespace brdf::exports
