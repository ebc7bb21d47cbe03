#include "tests/engine/engine_test_rig.h"

#include <gtest/gtest.h>

#include "core/plan/plan_json.h"

namespace brdf::testing {

using namespace std::chrono_literals;

daemon::SessionManager::Options ManagerOptions(bool pipelining) {
  daemon::SessionManager::Options o;
  o.rig_description = SimRigDescription();
  o.pipelining = pipelining;
  return o;
}

v1::Plan PlanFromJson(const std::string& json) {
  Result<v1::Plan> plan = plan::ParsePlanJson(json);
  EXPECT_TRUE(plan.ok()) << plan.status().ToString();
  return plan.ok() ? *plan : v1::Plan();
}

daemon::SessionId IdOf(const v1::Session& s) {
  Result<daemon::SessionId> id = daemon::ParseSessionId(s.session_id());
  return id.ok() ? *id : 0;
}

Operator::Operator(daemon::SessionManager& manager, FakeBench& bench, daemon::SessionId session,
                   bool answer_prompts)
    : manager_(manager), bench_(bench), session_(session), answering_(answer_prompts) {
  Result<std::shared_ptr<daemon::EventSubscription>> sub = manager_.Subscribe(session_);
  if (!sub.ok()) {
    errors_.push_back(sub.status().ToString());
    return;
  }
  sub_ = *sub;
  thread_ = std::thread([this] { Run(); });
}

Operator::~Operator() {
  Stop();
}

void Operator::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::vector<v1::SessionEvent> Operator::events() const {
  std::lock_guard lock(mu_);
  return events_;
}
std::vector<v1::Prompt> Operator::prompts_answered() const {
  std::lock_guard lock(mu_);
  return answered_;
}
std::vector<std::string> Operator::errors() const {
  std::lock_guard lock(mu_);
  return errors_;
}

void Operator::Run() {
  std::optional<v1::Prompt> open;
  while (!stop_ && !sub_->ended()) {
    std::optional<v1::SessionEvent> event = sub_->Next(20ms);
    if (event.has_value()) {
      std::lock_guard lock(mu_);
      events_.push_back(*event);
      if (event->has_prompt()) open = event->prompt();
      if (event->has_snapshot() && event->snapshot().has_pending_prompt()) {
        open = event->snapshot().pending_prompt();
      }
      if (event->has_state_changed() &&
          event->state_changed().to() != v1::SESSION_STATE_AWAITING_OPERATOR) {
        open.reset();
      }
    }
    if (!open.has_value() || !answering_) continue;
    // Do what the prompt asks on the bench, then confirm it.
    switch (open->kind()) {
      case v1::PROMPT_KIND_MOUNT_WHITE:
        bench_.SetMounted(FakeTarget::kWhite);
        break;
      case v1::PROMPT_KIND_MOUNT_SAMPLE:
        bench_.SetMounted(FakeTarget::kSample);
        break;
      case v1::PROMPT_KIND_CLOSE_SHUTTER:
        bench_.SetMounted(FakeTarget::kDark);
        break;
      default:
        break;  // relocations: the fake lamp and detector follow the stage
    }
    Result<v1::Session> answered =
        manager_.AnswerPrompt(session_, open->step_index(), "done", kTestOperator);
    std::lock_guard lock(mu_);
    if (answered.ok()) {
      answered_.push_back(*open);
    } else if (answered.status().code() != StatusCode::kFailedPrecondition) {
      // (FailedPrecondition: paused meanwhile; the prompt comes again on resume.)
      errors_.push_back(answered.status().ToString());
    }
    open.reset();
  }
}

v1::Session WaitForSession(daemon::SessionManager& manager, daemon::SessionId session,
                           const std::function<bool(const v1::Session&)>& done,
                           std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  v1::Session last;
  for (;;) {
    Result<v1::Session> s = manager.GetSession(session);
    if (s.ok()) {
      last = *s;
      if (done(last)) return last;
    }
    if (std::chrono::steady_clock::now() >= until) return last;
    std::this_thread::sleep_for(10ms);
  }
}

}  // namespace brdf::testing
