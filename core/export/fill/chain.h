// Filling an export's table without holes where a renderer looks: a FillChain asks a list of
// SpectrumSources in turn — by default the chosen interpolation method, then Delaunay, then the
// fitted analytic model — and each direction takes the first answer that is ok. It counts, per
// direction, which stage answered (its provenance: measured-interpolated, fallback, model), or
// that none did. Any export that fills a table over SpectrumSource (MERL, grid, RGL) adopts it by
// asking chain.Source() instead of its interpolator, and reading chain.Tally() afterwards.
//
// FillPolicy kNone is today's behaviour (the chosen method alone: NaN / −1 where it has no
// value); kChain the chain. Pure: no I/O.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "core/export/fill/spectrum_source.h"
#include "core/fit/fit.h"
#include "core/mutex.h"
#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

enum class FillPolicy { kNone, kChain };
const char* FillPolicyName(FillPolicy p);  // "none", "chain"
// "none" or "chain"; kInvalidArgument naming the value and the choices otherwise.
Result<FillPolicy> ParseFillPolicy(const std::string& name);

// Where a cell's value came from.
enum class Provenance {
  kInterpolated,  // the chosen method, from the measured readings
  kFallback,      // a fallback interpolation (Delaunay) where the chosen method had no value
  kModel,         // the fitted analytic model, where no interpolation had one
};
const char* ProvenanceName(Provenance p);  // "interpolated", "fallback", "model"

// Counts of one export's answers. Cells below the horizon are never asked: the export counts them.
struct FillTally {
  FillPolicy policy = FillPolicy::kNone;
  std::size_t interpolated = 0;
  std::size_t fallback = 0;
  std::size_t model = 0;
  std::size_t empty = 0;  // no stage had a value: NaN / −1 in the table
  std::size_t asked() const { return interpolated + fallback + model + empty; }
  double model_fraction() const;  // model / asked (0 when nothing was asked)
  // "chain: 12000 interpolated, 300 fallback, 25 model (0.20 %), 0 empty"
  std::string Summary() const;
  // {"policy": "chain", "interpolated": …, "fallback": …, "model": …, "empty": …,
  //  "model_fraction": …}
  std::string Json() const;
};

class FillChain {
 public:
  // A stage's batch (SpectrumSource::Spectra) may leave the rows it does not answer as they
  // were, unlike a SpectrumSource's: the chain fills NaN in the rows no stage answers.
  struct Stage {
    Provenance provenance;
    SpectrumSource source;
  };
  // stages[0] is the chosen method (kInterpolated); with kNone only it is asked. Must not be
  // empty; the stages (and what they point at) must outlive the chain.
  FillChain(FillPolicy policy, std::vector<Stage> stages);
  // Its sources point at it: it stays where it was made.
  FillChain(const FillChain&) = delete;
  FillChain& operator=(const FillChain&) = delete;

  // A source answering through the chain: a direction gets the first ok answer of the stages in
  // order (with kNone the first stage's, ok or not), and is counted. Batches go stage by stage,
  // each later stage asked only for the directions still without a value. Thread-safe. The chain
  // must outlive the source.
  SpectrumSource Source() const;
  // The counts so far (from every Source() call since the chain was made).
  FillTally Tally() const;

 private:
  struct Counters {
    std::atomic<std::size_t> interpolated{0}, fallback{0}, model{0}, empty{0};
  };
  void Count(std::size_t stage_or_empty, std::size_t n) const;  // stages.size(): empty
  interp::InterpStatus AnswerOne(const IsoDirection& at, std::span<double> out) const;
  void AnswerMany(std::span<const double> directions, std::span<interp::InterpStatus> statuses,
                  std::span<double> spectra) const;
  // A later stage without a batch path (the model) asked for the rows `missing` where they lie,
  // instead of through a gathered batch copied back: statuses[i] becomes kOk where it answers,
  // `still` gets the rows it did not answer (left NaN).
  static void AnswerInPlace(const SpectrumSource& source, std::span<const double> directions,
                            std::span<interp::InterpStatus> statuses, std::span<double> spectra,
                            std::size_t bands, const std::vector<std::size_t>& missing,
                            std::vector<std::size_t>& still);
  // What a batch's later stages work in. Kept between batches (one per thread at work), so that
  // their memory is allocated and first touched once per chain, not once per batch.
  struct Scratch {
    std::vector<std::size_t> missing, still;
    std::vector<double> directions, spectra;
    std::vector<interp::InterpStatus> statuses;
  };
  std::unique_ptr<Scratch> TakeScratch() const;
  void GiveScratch(std::unique_ptr<Scratch> scratch) const;

  FillPolicy policy_;
  std::vector<Stage> stages_;
  std::unique_ptr<Counters> counters_;
  mutable Mutex scratch_mu_;
  mutable std::vector<std::unique_ptr<Scratch>> scratch_ GUARDED_BY(scratch_mu_);
};

// The fitted Cook-Torrance model (core/fit) as a source: its per-band parameters evaluated at
// the direction, on the fit's wavelength grid; always ok. Directions below the surface answer 0.
SpectrumSource ModelSource(const fit::CookTorranceFit& model);

}  // namespace brdf::exports
