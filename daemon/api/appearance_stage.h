// A stage of the lit sphere's fill chain that is made only when a direction first needs it (the
// Delaunay fallback, the fitted model: daemon/api/appearance.cc); most sessions' spheres never
// ask. A stage likely to be needed soon can be started beforehand on a thread of its own (Start),
// so that it is made beside other work (the model fit beside the Delaunay build: both cores);
// a start nobody asked for is cancelled when the stage goes, and never shows in its errors.
//
// Thread-safe: the first lookup makes the stage (or waits for Start's) and the others wait for it,
// as SpectrumSource asks; error and Lasting are read once the lookups are done.
#pragma once

#include <atomic>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <string>

#include "core/call_context.h"
#include "core/export/fill/spectrum_source.h"
#include "core/interp/delaunay/near.h"
#include "core/status.h"

namespace brdf::daemon {

class LazyStage {
 public:
  // Makes the stage; `cancel` is cancelled when a stage started beforehand is no longer wanted.
  using Make = std::function<Result<exports::SpectrumSource>(const CancelToken& cancel)>;
  explicit LazyStage(Make make) : make_(std::move(make)) {}
  LazyStage(const LazyStage&) = delete;
  LazyStage& operator=(const LazyStage&) = delete;
  // Cancels a start that is still running and waits for it.
  ~LazyStage();

  // Starts making the stage on a thread of its own, unless started or made already.
  void Start();
  // The stage as a source: the first lookup makes it (or waits for Start's); a stage that cannot
  // be made answers no value (kOutsideHull), and says why in error().
  exports::SpectrumSource Source();
  // Why the stage could not be made, once a lookup asked for it ("" otherwise).
  const std::string& error() const;
  // Made, not needed, or failed for a reason of the readings (the same for every call on this
  // snapshot), not of this call (its deadline, a cancellation, the store).
  bool Lasting() const;

 private:
  void MakeNow();
  // The made stage, once a lookup needs it (made here or waited for).
  const std::optional<exports::SpectrumSource>& Made();

  Make make_;
  CancelToken cancel_;
  std::mutex mu_;
  bool made_ = false;          // MakeNow ran or is running (guarded by mu_)
  std::future<void> started_;  // valid once Start ran MakeNow on its own thread
  std::once_flag asked_once_;
  std::atomic<bool> asked_{false};  // a lookup needed the stage, and it is made
  std::optional<exports::SpectrumSource> source_;
  std::string error_;
  StatusCode code_ = StatusCode::kOk;
};

// The fill chain's Delaunay fallback for the few directions a lit sphere's index has no value
// for (on a large session: the colour's 45°:0°, on the readings' edge θo = 0): each answered
// from the readings near it when that is proved to be the whole triangulation's answer
// (core/interp/delaunay/near.h: the same simplex, the same value up to rounding), so that the
// whole triangulation (`whole`: seconds for 50,000 readings mirrored and swapped) is made only
// for a direction that cannot be proved so, and from the (kNearDirections + 1)-th direction on
// (a session with holes asks it for many pixels: one triangulation is then cheaper).
//
// Thread-safe, as SpectrumSource asks. `asked` runs once, at the first lookup (the appearance
// chain starts its model fit there, as the whole stage's make did).
class NearFallback {
 public:
  static constexpr std::size_t kNearDirections = 32;
  // Makes the near answers' point set: once, at the first lookup; an error sends every
  // direction to `whole`.
  using MakeNear = std::function<Result<interp::NearDelaunay>()>;
  NearFallback(MakeNear make_near, LazyStage& whole, std::function<void()> asked)
      : make_near_(std::move(make_near)), whole_source_(whole.Source()), asked_(std::move(asked)) {}
  NearFallback(const NearFallback&) = delete;
  NearFallback& operator=(const NearFallback&) = delete;

  exports::SpectrumSource Source();
  // Directions answered near the readings, so far.
  std::size_t near_answers() const;

 private:
  // The near answer at `at`, or nullopt when `whole` must answer it.
  std::optional<interp::InterpStatus> Near(const IsoDirection& at, std::span<double> out);

  MakeNear make_near_;
  const exports::SpectrumSource whole_source_;
  std::function<void()> asked_;
  mutable std::mutex mu_;
  bool first_ = true;                         // guarded by mu_
  bool to_whole_ = false;                     // guarded by mu_: every direction to `whole`
  std::optional<interp::NearDelaunay> near_;  // guarded by mu_
  std::size_t answered_ = 0;                  // guarded by mu_
};

}  // namespace brdf::daemon
