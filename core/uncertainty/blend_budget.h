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
//   - each shared component's input as three integers (the component's name by the list's
//     NameCodes, its sharing and the id it is shared through), compared instead of strings;
//   - the not_estimated entries, held by a list that consecutive readings with the same entries
//     share (a blend then adds them once by pointer instead of comparing ~100-character texts).
// Whoever builds a list of BlendBudgets (brdfd's index, the grid export's chain) holds its
// NameCodes: budgets are blended only with budgets of the same list. Pure: no I/O, no
// process-wide state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/uncertainty/budget.h"

namespace brdf::uncertainty {

// A small number for each distinct shared component's name, the same for the same name within one
// list of BlendBudgets. The names budget.cc gives shared components ("reference_signal",
// "white_standard", …, kSharedComponentNames) have fixed codes; any other name (a budget stored
// by another version) gets the next code of this table, so a table is extended rarely if ever.
// A copy of the table (a list copied to add to it) gives the same codes for the names it holds.
// Not thread-safe: one builder at a time.
class NameCodes {
 public:
  std::uint32_t Code(std::string_view name);
  // How many names outside kSharedComponentNames it has coded.
  std::size_t others() const { return others_.size(); }

 private:
  std::vector<std::string> others_;
};

// The shared components' names budget.cc gives (EstimateReadingBudget), in a fixed order.
inline constexpr std::string_view kSharedComponentNames[] = {
    "reference_signal",    "dark_signal",          "white_standard",      "reference_pose",
    "lamp_drift",          "wavelength_scale",     "stray_light",         "pose_alignment_alpha",
    "pose_alignment_beta", "pose_alignment_gamma", "pose_alignment_delta"};

// The input one shared component is shared through: its name, its sharing and the thing's id
// (blend.h: contributions of the same input add linearly).
struct SharedKey {
  std::uint32_t name = 0;  // NameCodes::Code
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
// `independent`; its value and combined are not kept), its names coded by `codes` (the list's).
// kInvalidArgument when its independent part or a shared component does not have the same number
// of bands as its combined. `notes`: a list to share when it holds the same entries as
// budget.not_estimated (the previous reading's), else a new one is made.
Result<BlendBudget> ToBlendBudget(const ReadingBudget& budget, NameCodes& codes,
                                  std::shared_ptr<const std::vector<std::string>> notes = nullptr);

// What `b`'s members hold on the heap (its vectors, each with glibc's ~16 bytes of bookkeeping),
// not sizeof(b) itself; its not_estimated list too (make_shared's block, the vector, the strings
// beyond their inline buffer) when `count_notes`: a list consecutive budgets share is counted
// with the first of them. For the caches that bound their memory by it (brdfd's index, the
// export's loaded sessions).
std::size_t HeapBytes(const BlendBudget& b, bool count_notes);

// A list's BlendBudgets made in order (brdfd's index, the grid export's chain): ToBlendBudget with
// the list's NameCodes, each budget's not_estimated shared with the previous one's when it holds
// the same entries. A copy goes on with the same codes.
class BlendBudgetMaker {
 public:
  // The next budget's form (ToBlendBudget's errors); *new_notes, when given, says whether its
  // not_estimated list is a new one (not the previous budget's).
  Result<BlendBudget> Make(const ReadingBudget& budget, bool* new_notes = nullptr);

 private:
  NameCodes codes_;
  std::shared_ptr<const std::vector<std::string>> last_notes_;  // the last budget made's
};

}  // namespace brdf::uncertainty
