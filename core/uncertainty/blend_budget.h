// BlendBudget: what an interpolated value's measurement uncertainty reads of one reading's budget
// (blend.h), in the form an index keeps for thousands of blends a second (brdfd's interpolation
// index; docs/uncertainty.md, "Interpolated values"):
//   - the independent part, sqrt(Σ independent uⱼ²) per band, in double (the held-out
//     calibration's noise reads it too, held_out.h, and stays the same bits);
//   - the shared components' contributions as floats, one row of `bands` after the other in one
//     block: half the bytes a blend reads (4 vertices × 7 shared inputs × 101 bands, ~11 kB an
//     answer instead of ~23 kB). An uncertainty has two significant digits of meaning (GUM 7.2.6)
//     and the API sends it as floats; a float's rounding (2⁻²⁴ relative) changes an answer's
//     measurement part by at most a few units in its last float place;
//   - each shared component's input as three integers (the component's name by NameCode, its
//     sharing and the id it is shared through), compared instead of strings;
//   - the not_estimated entries, held by a list that consecutive readings with the same entries
//     share (a blend then adds them once by pointer instead of comparing ~100-character texts).
// Pure: no I/O (NameCode keeps a process-wide table of the names it has seen, under a mutex).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/uncertainty/budget.h"

namespace brdf::uncertainty {

// A small number for each distinct component name, the same for the same name in the whole
// process (names are the budget's vocabulary: "reference_signal", "white_standard", …).
std::uint32_t NameCode(std::string_view name);

// The input one shared component is shared through: its name, its sharing and the thing's id
// (blend.h: contributions of the same input add linearly).
struct SharedKey {
  std::uint32_t name = 0;  // NameCode
  Sharing kind = Sharing::kIndependent;
  std::int64_t id = 0;
  friend bool operator==(const SharedKey&, const SharedKey&) = default;
};

struct BlendBudget {
  std::size_t bands = 0;
  std::vector<double> independent;  // bands values
  std::vector<SharedKey> keys;      // one per shared component, in the budget's order
  std::vector<float> shared_rows;   // keys.size() rows of `bands` values, in the keys' order
  std::shared_ptr<const std::vector<std::string>> not_estimated;  // never null

  // Shared component j's contributions (bands values).
  const float* row(std::size_t j) const { return shared_rows.data() + j * bands; }
};

// The blend's form of `budget` (its independent components are already summed in
// `independent`; its value and combined are not kept). kInvalidArgument when its independent
// part or a shared component does not have the same number of bands as its combined.
// `notes`: a list to share when it holds the same entries as budget.not_estimated (the previous
// reading's), else a new one is made.
Result<BlendBudget> ToBlendBudget(const ReadingBudget& budget,
                                  std::shared_ptr<const std::vector<std::string>> notes = nullptr);

}  // namespace brdf::uncertainty
