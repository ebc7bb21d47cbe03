#include "daemon/rig/port.h"

#include <utility>

#include "daemon/engine/adaptive_rounds.h"

namespace brdf::daemon {
namespace {

// A WatchSession subscription on the manager's event bus.
class EventWatch final : public SessionWatch {
 public:
  explicit EventWatch(std::shared_ptr<EventSubscription> subscription)
      : subscription_(std::move(subscription)) {}

  std::optional<v1::SessionEvent> Next(std::chrono::steady_clock::duration wait) override {
    return subscription_->Next(wait);
  }
  bool ended() const override { return subscription_->ended(); }
  void Close() override { subscription_->Close(); }
  void OnEvent(std::function<void()> wake) override { subscription_->SetListener(std::move(wake)); }

 private:
  std::shared_ptr<EventSubscription> subscription_;
};

}  // namespace

Result<v1::Session> ManagerRigPort::SubmitPlan(const v1::Plan& plan, const Actor& actor,
                                               bool start_now) {
  return manager_.SubmitPlan(plan, actor, start_now);
}

plan::PlanAnalysis ManagerRigPort::ValidatePlan(const v1::Plan& plan, double time_scale) const {
  return manager_.ValidatePlan(plan, time_scale);
}

Result<v1::Session> ManagerRigPort::Start(SessionId session, const Actor& actor) {
  return manager_.Start(session, actor);
}

Result<v1::Session> ManagerRigPort::Pause(SessionId session, PauseMode mode, const Actor& actor,
                                          bool* already_paused) {
  return manager_.Pause(session, mode, actor, already_paused);
}

Result<v1::Session> ManagerRigPort::Resume(SessionId session, const Actor& actor) {
  return manager_.Resume(session, actor);
}

Result<v1::Session> ManagerRigPort::Abort(SessionId session, const std::string& reason,
                                          const Actor& actor) {
  return manager_.Abort(session, reason, actor);
}

Result<v1::Session> ManagerRigPort::AnswerPrompt(SessionId session, int step_index,
                                                 const std::string& note, const Actor& actor) {
  return manager_.AnswerPrompt(session, step_index, note, actor);
}

v1::RigStatus ManagerRigPort::GetRigStatus() const {
  return manager_.GetRigStatus();
}

Result<std::unique_ptr<SessionWatch>> ManagerRigPort::Watch(SessionId session) {
  BRDF_ASSIGN_OR_RETURN(std::shared_ptr<EventSubscription> subscribed, manager_.Subscribe(session));
  return std::unique_ptr<SessionWatch>(std::make_unique<EventWatch>(std::move(subscribed)));
}

Result<std::vector<v1::AdaptiveRound>> ManagerRigPort::AdaptiveRounds(SessionId session) {
  BRDF_ASSIGN_OR_RETURN(std::shared_ptr<const SessionPlan> kept, manager_.Plan(session));
  if (!kept->plan.has_adaptive()) return std::vector<v1::AdaptiveRound>{};
  return StoredRounds(*manager_.store(), session, kept->plan, manager_.options().rig_description);
}

}  // namespace brdf::daemon
