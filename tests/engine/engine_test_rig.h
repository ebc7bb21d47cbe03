// What the engine tests stand on: the in-process fake meter and stage behind the driver
// interfaces (tests/support/fakes/rig.h), a real SQLite file in a temporary directory, and an
// "operator" that answers the session's prompts the way a person would: it mounts the white
// standard, the sample or closes the shutter on the fake bench, then answers the prompt. The
// real drivers and their wire protocols are exercised against brdf-sim elsewhere (tests/sim,
// tests/drivers_*, tests/daemon, tests/faults).
//
// Simulated time runs kTimeScale times faster (the meter's integrations and the stage's moves).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/plan/rig_description.h"
#include "daemon/engine/rig.h"
#include "daemon/engine/session_manager.h"
#include "storage/session_store.h"
#include "tests/support/fakes/rig.h"
#include "tests/support/test_env.h"

namespace brdf::testing {

inline constexpr double kTimeScale = 50;

daemon::SessionManager::Options ManagerOptions(bool pipelining = true);

// A plan from its JSON form (fails the test when it does not parse).
v1::Plan PlanFromJson(const std::string& json);

// Acts as the operator on one session: watches it (SessionManager::Subscribe) and answers every
// prompt after doing what it asks on the fake bench. Keeps every event it saw. Runs on its own
// thread until the session ends or Stop().
class Operator {
 public:
  Operator(daemon::SessionManager& manager, FakeBench& bench, daemon::SessionId session,
           bool answer_prompts = true);
  ~Operator();

  void Stop();
  // Answer prompts from now on (or not).
  void set_answering(bool on) { answering_ = on; }

  std::vector<v1::SessionEvent> events() const;
  std::vector<v1::Prompt> prompts_answered() const;
  std::vector<std::string> errors() const;

 private:
  void Run();

  daemon::SessionManager& manager_;
  FakeBench& bench_;
  daemon::SessionId session_;
  std::atomic<bool> answering_;
  std::atomic<bool> stop_{false};
  std::shared_ptr<daemon::EventSubscription> sub_;
  mutable std::mutex mu_;
  std::vector<v1::SessionEvent> events_;
  std::vector<v1::Prompt> answered_;
  std::vector<std::string> errors_;
  std::thread thread_;
};

// Polls GetSession until `done` holds or `timeout` passes; returns the last session seen.
v1::Session WaitForSession(daemon::SessionManager& manager, daemon::SessionId session,
                           const std::function<bool(const v1::Session&)>& done,
                           std::chrono::milliseconds timeout = std::chrono::seconds(20));

inline bool IsState(const v1::Session& s, v1::SessionState state) {
  return s.state() == state;
}

daemon::SessionId IdOf(const v1::Session& s);

inline const daemon::Actor kTestOperator{"operator", "engine-test"};

}  // namespace brdf::testing
