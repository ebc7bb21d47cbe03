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

}  // namespace brdf::daemon
