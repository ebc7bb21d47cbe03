// WorkPermits: the few permits under which analysts' heavy streams compute (exports,
// InterpolateBatch, RenderAppearance; stream_registry.h), shared fairly between tokens.
//
// A free permit goes to the waiting stream whose token holds the fewest permits, the earliest
// arrived among those; one analyst's hundred exports then do not keep another's one waiting
// behind them. A permit is handed to the chosen waiter and only that waiter is woken: with
// hundreds of streams waiting (bench/daemon/control_plane.sh: 300), waking them all at every
// release to let each look whether it is its turn cost the daemon a storm of wake-ups, the cores
// the control plane needs (issue 40).
#pragma once

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <string>

#include "core/mutex.h"

namespace brdf::daemon {

class WorkPermits {
 public:
  // permits ≥ 1 (fewer is taken as 1).
  explicit WorkPermits(int permits);
  WorkPermits(const WorkPermits&) = delete;
  WorkPermits& operator=(const WorkPermits&) = delete;

  int permits() const { return permits_; }

  // Waits for a permit for a stream of `token` ("": a call without a token): true with one held,
  // false when `cancelled` turned true first (asked at once and every half second while
  // it waits: the synchronous API has no wake-up for a cancelled call). Give it back with
  // Release.
  bool Acquire(const std::string& token, const std::function<bool()>& cancelled);
  void Release(const std::string& token);

  // Permits held now, and streams waiting for one.
  int working() const;
  int waiting() const;

 private:
  struct Waiter {
    explicit Waiter(const std::string& t) : token(t) {}
    const std::string& token;
    bool granted = false;
    CondVar granted_cv;
  };
  // Hands free permits to the chosen waiters and wakes each.
  void GrantLocked() REQUIRES(mu_);
  int HeldLocked(const std::string& token) const REQUIRES(mu_);

  const int permits_;
  mutable Mutex mu_;
  int working_ GUARDED_BY(mu_) = 0;
  std::map<std::string, int> held_ GUARDED_BY(mu_);  // permits held, per token
  std::list<Waiter*> waiting_ GUARDED_BY(mu_);       // in order of arrival
};

}  // namespace brdf::daemon
