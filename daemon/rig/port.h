// ManagerRigPort: brdfd's rig as the API drives it (api/rig_port.h): the operator's verbs,
// ValidatePlan and GetRigStatus on its SessionManager, WatchSession on its event bus.
#pragma once

#include <memory>

#include "daemon/api/rig_port.h"
#include "daemon/engine/session_manager.h"

namespace brdf::daemon {

class ManagerRigPort final : public RigPort {
 public:
  // `manager` must outlive the port.
  explicit ManagerRigPort(SessionManager& manager) : manager_(manager) {}

  Result<v1::Session> SubmitPlan(const v1::Plan& plan, const Actor& actor, bool start_now) override;
  plan::PlanAnalysis ValidatePlan(const v1::Plan& plan, double time_scale) const override;
  Result<v1::Session> Start(SessionId session, const Actor& actor) override;
  Result<v1::Session> Pause(SessionId session, PauseMode mode, const Actor& actor,
                            bool* already_paused) override;
  Result<v1::Session> Resume(SessionId session, const Actor& actor) override;
  Result<v1::Session> Abort(SessionId session, const std::string& reason,
                            const Actor& actor) override;
  Result<v1::Session> AnswerPrompt(SessionId session, int step_index, const std::string& note,
                                   const Actor& actor) override;
  v1::RigStatus GetRigStatus() const override;
  Result<std::unique_ptr<SessionWatch>> Watch(SessionId session) override;
  Result<std::vector<v1::AdaptiveRound>> AdaptiveRounds(SessionId session) override;

 private:
  SessionManager& manager_;
};

}  // namespace brdf::daemon
