// `brdf-interp synth`: writes a synthetic samples CSV (synthetic_samples.h), or with
// --coordinates-only a queries CSV of the same points.
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>

namespace brdf::interp_tool {

struct SynthRequest {
  std::string grid = "paper";  // "paper" or "random"
  std::size_t count = 0;       // random: number of points
  std::uint64_t seed = 1;
  int dims = 3;  // random only; the paper's grid is 3D
  bool coordinates_only = false;
  std::size_t bands =
      101;  // 380–780 nm: 101 (4 nm, PR-650), 201 (2 nm, PR-670), 401 (1 nm, CS-2000)
  std::string output_path;  // "" or "-": standard output
};

int RunSynth(const SynthRequest& request, std::ostream& err);

}  // namespace brdf::interp_tool
