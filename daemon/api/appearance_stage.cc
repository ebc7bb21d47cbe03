#include "daemon/api/appearance_stage.h"

#include <utility>

namespace brdf::daemon {

LazyStage::~LazyStage() {
  if (started_.valid()) {
    cancel_.Cancel("the lit sphere did not need this stage");
    started_.wait();
  }
}

void LazyStage::Start() {
  const std::lock_guard lock(mu_);
  if (made_) return;
  made_ = true;
  started_ = std::async(std::launch::async, [this] { MakeNow(); });
}

void LazyStage::MakeNow() {
  Result<exports::SpectrumSource> made = make_(cancel_);
  if (made.ok()) {
    source_.emplace(*std::move(made));
  } else {
    error_ = made.status().message();
    code_ = made.status().code();
  }
}

const std::optional<exports::SpectrumSource>& LazyStage::Made() {
  std::call_once(asked_once_, [this] {
    bool make_here = false;
    {
      const std::lock_guard lock(mu_);
      make_here = !made_;
      made_ = true;
    }
    if (make_here) {
      MakeNow();
    } else {
      started_.wait();
    }
    asked_.store(true, std::memory_order_release);
  });
  return source_;
}

exports::SpectrumSource LazyStage::Source() {
  return [this](const IsoDirection& at, std::span<double> out) {
    const std::optional<exports::SpectrumSource>& source = Made();
    return source ? (*source)(at, out) : interp::InterpStatus::kOutsideHull;
  };
}

const std::string& LazyStage::error() const {
  static const std::string kNone;
  return asked_.load(std::memory_order_acquire) ? error_ : kNone;
}

bool LazyStage::Lasting() const {
  return !asked_.load(std::memory_order_acquire) || error_.empty() ||
         code_ == StatusCode::kFailedPrecondition || code_ == StatusCode::kInvalidArgument ||
         code_ == StatusCode::kNotFound;
}

}  // namespace brdf::daemon
