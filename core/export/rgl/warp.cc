#include "core/export/rgl/warp.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace brdf::exports {
namespace {

constexpr float kOneMinusEpsilon = 0.999999940395355225f;

// The largest i in [0, size − 2] with pred(i) true (pred true then false along i); 0 if none.
template <typename Pred>
std::size_t FindInterval(std::size_t size, const Pred& pred) {
  std::size_t lo = 0, hi = size >= 2 ? size - 2 : 0;
  if (!pred(lo)) return 0;
  while (lo < hi) {
    const std::size_t mid = (lo + hi + 1) / 2;
    if (pred(mid)) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  return lo;
}

}  // namespace

Warp2D::Warp2D(std::size_t nx, std::size_t ny, const float* data,
               std::vector<std::vector<float>> params, bool normalize, bool build_cdf)
    : nx_(nx), ny_(ny), params_(std::move(params)) {
  if (build_cdf) normalize = true;
  std::size_t slices = 1;
  strides_.assign(params_.size(), 0);
  for (std::size_t d = params_.size(); d-- > 0;) {
    strides_[d] = params_[d].size() > 1 ? slices : 0;
    slices *= params_[d].size();
  }
  const std::size_t n = nx * ny;
  data_.resize(slices * n);
  if (build_cdf) {
    marginal_cdf_.resize(slices * ny);
    conditional_cdf_.resize(slices * n);
  }
  for (std::size_t s = 0; s < slices; ++s) {
    const float* in = data + s * n;
    float* out = data_.data() + s * n;
    float scale = 1.0f / static_cast<float>((nx - 1) * (ny - 1));
    if (build_cdf) {
      float* cond = conditional_cdf_.data() + s * n;
      float* marg = marginal_cdf_.data() + s * ny;
      for (std::size_t y = 0; y < ny; ++y) {
        double sum = 0;
        cond[y * nx] = 0;
        for (std::size_t x = 0; x + 1 < nx; ++x) {
          sum += 0.5 * (static_cast<double>(in[y * nx + x]) + in[y * nx + x + 1]);
          cond[y * nx + x + 1] = static_cast<float>(sum);
        }
      }
      double sum = 0;
      marg[0] = 0;
      for (std::size_t y = 0; y + 1 < ny; ++y) {
        sum += 0.5 * (static_cast<double>(cond[(y + 1) * nx - 1]) + cond[(y + 2) * nx - 1]);
        marg[y + 1] = static_cast<float>(sum);
      }
      scale = 1.0f / marg[ny - 1];
      for (std::size_t i = 0; i < n; ++i) cond[i] *= scale;
      for (std::size_t i = 0; i < ny; ++i) marg[i] *= scale;
    } else if (normalize) {
      double sum = 0;
      for (std::size_t y = 0; y + 1 < ny; ++y) {
        for (std::size_t x = 0; x + 1 < nx; ++x) {
          const std::size_t i = y * nx + x;
          sum += 0.25 * (static_cast<double>(in[i]) + in[i + 1] + in[i + nx] + in[i + nx + 1]);
        }
      }
      scale = static_cast<float>(1.0 / sum);
    }
    for (std::size_t i = 0; i < n; ++i) out[i] = in[i] * scale;
  }
}

Warp2D::Blend Warp2D::BlendAt(const float* param) const {
  Blend b;
  for (std::size_t d = 0; d < params_.size(); ++d) {
    const std::vector<float>& v = params_[d];
    if (v.size() == 1) continue;
    const float p = param[d];
    const std::size_t k = FindInterval(v.size(), [&](std::size_t i) { return v[i] <= p; });
    const float w1 = std::clamp((p - v[k]) / (v[k + 1] - v[k]), 0.0f, 1.0f);
    b.w[d][0] = 1.0f - w1;
    b.w[d][1] = w1;
    b.slice += strides_[d] * k;
  }
  return b;
}

float Warp2D::Lookup(const std::vector<float>& table, std::size_t i, std::size_t slice_size,
                     const Blend& b) const {
  const std::size_t dims = params_.size();
  float sum = 0;
  for (std::size_t corner = 0; corner < (std::size_t{1} << dims); ++corner) {
    float w = 1;
    std::size_t at = i;
    for (std::size_t d = 0; d < dims; ++d) {
      const std::size_t bit = (corner >> d) & 1;
      w *= b.w[d][bit];
      at += bit * strides_[d] * slice_size;
    }
    if (w != 0) sum += w * table[at];
  }
  return sum;
}

float Warp2D::Eval(float x, float y, const float* param) const {
  const Blend b = BlendAt(param);
  const float px = x * static_cast<float>(nx_ - 1), py = y * static_cast<float>(ny_ - 1);
  const std::size_t ox = std::min(static_cast<std::size_t>(std::max(px, 0.0f)), nx_ - 2);
  const std::size_t oy = std::min(static_cast<std::size_t>(std::max(py, 0.0f)), ny_ - 2);
  const float w1x = px - static_cast<float>(ox), w1y = py - static_cast<float>(oy);
  const float w0x = 1 - w1x, w0y = 1 - w1y;
  const std::size_t size = nx_ * ny_;
  const std::size_t i = ox + oy * nx_ + b.slice * size;
  const float v00 = Lookup(data_, i, size, b), v10 = Lookup(data_, i + 1, size, b),
              v01 = Lookup(data_, i + nx_, size, b), v11 = Lookup(data_, i + nx_ + 1, size, b);
  return (w0y * (w0x * v00 + w1x * v10) + w1y * (w0x * v01 + w1x * v11)) *
         static_cast<float>((nx_ - 1) * (ny_ - 1));
}

WarpPoint Warp2D::Sample(float sx, float sy, const float* param) const {
  sx = std::clamp(sx, 1 - kOneMinusEpsilon, kOneMinusEpsilon);
  sy = std::clamp(sy, 1 - kOneMinusEpsilon, kOneMinusEpsilon);
  const Blend b = BlendAt(param);
  const std::size_t size = nx_ * ny_;
  const std::size_t moff = b.slice * ny_;
  auto marginal = [&](std::size_t i) { return Lookup(marginal_cdf_, moff + i, ny_, b); };
  const std::size_t row = FindInterval(ny_, [&](std::size_t i) { return marginal(i) < sy; });
  sy -= marginal(row);
  std::size_t off = row * nx_ + b.slice * size;
  const float r0 = Lookup(conditional_cdf_, off + nx_ - 1, size, b);
  const float r1 = Lookup(conditional_cdf_, off + 2 * nx_ - 1, size, b);
  bool is_const = std::abs(r0 - r1) < 1e-4f * (r0 + r1);
  sy = is_const ? 2 * sy : r0 - std::sqrt(std::max(0.0f, r0 * r0 - 2 * sy * (r0 - r1)));
  sy /= is_const ? r0 + r1 : r0 - r1;
  sx *= (1 - sy) * r0 + sy * r1;
  auto conditional = [&](std::size_t i) {
    return (1 - sy) * Lookup(conditional_cdf_, off + i, size, b) +
           sy * Lookup(conditional_cdf_, off + nx_ + i, size, b);
  };
  const std::size_t col = FindInterval(nx_, [&](std::size_t i) { return conditional(i) < sx; });
  sx -= conditional(col);
  off += col;
  const float v00 = Lookup(data_, off, size, b), v10 = Lookup(data_, off + 1, size, b),
              v01 = Lookup(data_, off + nx_, size, b), v11 = Lookup(data_, off + nx_ + 1, size, b);
  const float c0 = (1 - sy) * v00 + sy * v01, c1 = (1 - sy) * v10 + sy * v11;
  is_const = std::abs(c0 - c1) < 1e-4f * (c0 + c1);
  sx = is_const ? 2 * sx : c0 - std::sqrt(std::max(0.0f, c0 * c0 - 2 * sx * (c0 - c1)));
  sx /= is_const ? c0 + c1 : c0 - c1;
  return {(static_cast<float>(col) + sx) / static_cast<float>(nx_ - 1),
          (static_cast<float>(row) + sy) / static_cast<float>(ny_ - 1),
          ((1 - sx) * c0 + sx * c1) * static_cast<float>((nx_ - 1) * (ny_ - 1))};
}

WarpPoint Warp2D::Invert(float x, float y, const float* param) const {
  const Blend b = BlendAt(param);
  float sx = x * static_cast<float>(nx_ - 1), sy = y * static_cast<float>(ny_ - 1);
  const std::size_t px = std::min(static_cast<std::size_t>(std::max(sx, 0.0f)), nx_ - 2);
  const std::size_t py = std::min(static_cast<std::size_t>(std::max(sy, 0.0f)), ny_ - 2);
  sx -= static_cast<float>(px);
  sy -= static_cast<float>(py);
  const std::size_t size = nx_ * ny_;
  std::size_t off = px + py * nx_ + b.slice * size;
  const float v00 = Lookup(data_, off, size, b), v10 = Lookup(data_, off + 1, size, b),
              v01 = Lookup(data_, off + nx_, size, b), v11 = Lookup(data_, off + nx_ + 1, size, b);
  const float c0 = (1 - sy) * v00 + sy * v01, c1 = (1 - sy) * v10 + sy * v11;
  const float pdf = (1 - sx) * c0 + sx * c1;
  sx *= c0 + 0.5f * sx * (c1 - c0);
  sx += (1 - sy) * Lookup(conditional_cdf_, off, size, b) +
        sy * Lookup(conditional_cdf_, off + nx_, size, b);
  off = py * nx_ + b.slice * size;
  const float r0 = Lookup(conditional_cdf_, off + nx_ - 1, size, b);
  const float r1 = Lookup(conditional_cdf_, off + 2 * nx_ - 1, size, b);
  sx /= (1 - sy) * r0 + sy * r1;
  sy *= r0 + 0.5f * sy * (r1 - r0);
  sy += Lookup(marginal_cdf_, py + b.slice * ny_, ny_, b);
  return {sx, sy, pdf * static_cast<float>((nx_ - 1) * (ny_ - 1))};
}

}  // namespace brdf::exports
