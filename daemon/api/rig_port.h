// RigPort: the rig behind a server, when it has one (brdfd; brdf-archive has none). The Control
// service's rig verbs (SubmitPlan, ValidatePlan, Start/Pause/Resume/Abort, AnswerPrompt),
// GetRigStatus, WatchSession and ListAdaptiveRounds go through it; without one they answer
// FAILED_PRECONDITION naming the session's rig (api/control.cc), except ListAdaptiveRounds, which
// brdf-archive answers from the rounds the rigs shipped (SessionCatalogue::AdaptiveRounds). brdfd
// plugs in its session manager (rig/port.h).
//
// Every verb returns the session as the API shows it after the call, or a Status whose code maps
// onto a gRPC code (api/common.h: ToGrpcStatus); each is audited by the rig with `actor`.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/plan/analyze_plan.h"
#include "core/status.h"
#include "daemon/sessions/pause_mode.h"
#include "daemon/sessions/session_id.h"

namespace brdf::daemon {

// One WatchSession stream's subscription: a snapshot, then every event until the session ends.
class SessionWatch {
 public:
  virtual ~SessionWatch() = default;
  // The next event, waiting up to `wait`; nullopt when none came in time or the watch ended.
  virtual std::optional<v1::SessionEvent> Next(std::chrono::steady_clock::duration wait) = 0;
  // The session's last event was read: nothing more will come.
  virtual bool ended() const = 0;
  // The watcher went away.
  virtual void Close() = 0;
  // `wake` is called after each event is queued (on the publisher's thread: it must not block),
  // so a watch served without a thread of its own (api/pumped_stream.h) calls Next(0) only when
  // there may be something. Without it (the default) such a watch looks every second.
  virtual void OnEvent(std::function<void()> wake) { (void)wake; }
};

class RigPort {
 public:
  virtual ~RigPort() = default;

  virtual Result<v1::Session> SubmitPlan(const v1::Plan& plan, const Actor& actor,
                                         bool start_now) = 0;
  // The plan checked and summarised against this rig, for devices `time_scale` (> 0) times
  // faster (0: the rig's own, its [rig] time_scale); nothing stored.
  virtual plan::PlanAnalysis ValidatePlan(const v1::Plan& plan, double time_scale) const = 0;
  virtual Result<v1::Session> Start(SessionId session, const Actor& actor) = 0;
  // `already_paused` (not null): whether the session was PAUSED before this call, as the rig
  // knew it when the verb ran (no second read of the session).
  virtual Result<v1::Session> Pause(SessionId session, PauseMode mode, const Actor& actor,
                                    bool* already_paused) = 0;
  virtual Result<v1::Session> Resume(SessionId session, const Actor& actor) = 0;
  virtual Result<v1::Session> Abort(SessionId session, const std::string& reason,
                                    const Actor& actor) = 0;
  virtual Result<v1::Session> AnswerPrompt(SessionId session, int step_index,
                                           const std::string& note, const Actor& actor) = 0;

  virtual v1::RigStatus GetRigStatus() const = 0;

  // A watch of one session (kNotFound when there is no such session).
  virtual Result<std::unique_ptr<SessionWatch>> Watch(SessionId session) = 0;

  // An adaptive session's stored rounds, oldest first, with what each was predicted to gain and
  // cost (ListAdaptiveRounds); empty for a session of another kind. kNotFound when there is no
  // such session.
  virtual Result<std::vector<v1::AdaptiveRound>> AdaptiveRounds(SessionId session) = 0;
};

}  // namespace brdf::daemon
