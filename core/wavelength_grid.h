// A regular wavelength sampling: `count` bands starting at `start_nm`, `step_nm` apart.
// The PR-650 reports 380–780 nm every 4 nm (101 bands); other meters differ (the PR-670: 2 nm,
// 201 bands), so nothing in brdfd assumes one grid.
#pragma once

#include <cmath>
#include <cstddef>

namespace brdf {

struct WavelengthGrid {
  double start_nm = 380;
  double step_nm = 4;
  std::size_t count = 101;

  double at(std::size_t i) const { return start_nm + step_nm * static_cast<double>(i); }
  double last_nm() const { return count == 0 ? start_nm : at(count - 1); }
  bool valid() const { return count > 0 && step_nm > 0 && std::isfinite(start_nm); }
  friend bool operator==(const WavelengthGrid&, const WavelengthGrid&) = default;

  // The PR-650 SpectraScan's layout (D120 reports it as 101, 380., 780., 4.).
  static WavelengthGrid Pr650() { return {380, 4, 101}; }
};

}  // namespace brdf
