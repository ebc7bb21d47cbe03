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

std::optional<interp::InterpStatus> NearFallback::Near(const IsoDirection& at,
                                                       std::span<double> out) {
  const std::lock_guard lock(mu_);
  if (first_) {
    first_ = false;
    if (asked_) asked_();
    if (Result<interp::NearDelaunay> made = make_near_(); made.ok()) {
      near_.emplace(std::move(made).value());
    } else {
      to_whole_ = true;  // the whole stage says why, if it cannot be made either
    }
  }
  if (to_whole_ || answered_ >= kNearDirections) {
    to_whole_ = true;
    return std::nullopt;
  }
  const double query[3] = {at.theta_i, at.theta_o, at.phi};
  std::optional<interp::InterpStatus> answer = near_->SpectrumAt(query, out);
  if (!answer) {
    to_whole_ = true;
    return std::nullopt;
  }
  ++answered_;
  return answer;
}

exports::SpectrumSource NearFallback::Source() {
  return [this](const IsoDirection& at, std::span<double> out) {
    if (std::optional<interp::InterpStatus> answer = Near(at, out)) return *answer;
    return whole_source_(at, out);
  };
}

std::size_t NearFallback::near_answers() const {
  const std::lock_guard lock(mu_);
  return answered_;
}

}  // namespace brdf::daemon
