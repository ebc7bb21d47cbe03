// IndexSamples: one session's sample sets, one per quantity, grown a committed reading at a time
// (IndexCache's part that turns readings into interp::SampleSets). Each reading goes through
// core/readings' ReadingDeriver, which keeps the references and darks it has seen, so a sample is
// derived from the reference and dark it names without asking the store.
//
// Two generations: Fold adds to the working sets (copies of the published ones that share their
// storage, made on the first Fold after a Publish); Publish makes them the published sets, which
// snapshots and queries read. Published sets are never changed afterwards, so an index over them
// stays valid while later readings are folded. Not thread-safe: IndexCache serialises Fold and
// Publish (the entry's build lock) and readers of the published state (its state lock).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/readings/derive.h"
#include "core/readings/quantity.h"
#include "core/wavelength_grid.h"
#include "daemon/index/budgets.h"
#include "storage/records.h"

namespace brdf::daemon {

class IndexSamples {
 public:
  // What a session's sets are over: its readings up to through_id, with the sample readings left
  // out per quantity (how many, and why the first one was).
  struct State {
    std::array<std::shared_ptr<const interp::SampleSet>, kQuantityCount> sets;
    std::array<std::size_t, kQuantityCount> skipped{};
    std::array<std::string, kQuantityCount> skipped_detail;
    std::int64_t through_id = 0;  // every reading with id ≤ this was folded
    // The BRDF set's readings' uncertainty budgets, position for position (the stored budgets
    // are of the BRDF; docs/uncertainty.md).
    BudgetList brdf_budgets;
  };

  // anisotropic: (θi, φi, θo, φo) coordinates, else (θi, θo, φ); ρw (and ρw(λ) when the plan's
  // sample block gives it): the session's.
  IndexSamples(bool anisotropic, double white_reflectance,
               std::optional<Spectrum> white_spectrum = std::nullopt);

  // Folds one reading, in the order they were taken. A reading at or before the last one folded
  // is ignored (the first load from the store and the commit events may both hand it over).
  // Returns whether it was folded.
  bool Fold(const storage::ReadingRecord& record);

  // Makes the working sets the published ones. True when a set grew (the indexes over the old
  // ones are then stale).
  bool Publish();

  // True when readings were folded since the last Publish.
  bool changed() const { return working_.through_id != published_.through_id; }
  const State& published() const { return published_; }
  bool anisotropic() const { return anisotropic_; }
  int dims() const { return anisotropic_ ? 4 : 3; }
  // The session's grid: its first usable sample reading's, else its first reading's (a white
  // reference alone already tells it; storage keeps one grid per session). Before any reading
  // nothing can be answered and the PR-650's is only the answers' label.
  WavelengthGrid grid() const {
    return deriver_.grid().value_or(first_grid_.value_or(WavelengthGrid::Pr650()));
  }

 private:
  void Add(Quantity q, const storage::ReadingRecord& record, std::span<const double> coords,
           const std::vector<double>& values);
  void Skip(Quantity q, const std::string& why);

  const bool anisotropic_;
  ReadingDeriver deriver_;
  std::optional<WavelengthGrid> first_grid_;  // the first reading's, of any kind
  State published_;
  State working_;  // published_ plus what was folded since; grown_ holds its sets that grew
  std::array<std::shared_ptr<interp::SampleSet>, kQuantityCount> grown_;
};

}  // namespace brdf::daemon
