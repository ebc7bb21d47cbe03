#include "tools/brdfctl/commands/control.h"

#include <CLI/CLI.hpp>
#include <memory>

#include "core/adaptive/budget_text.h"
#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/session_text.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/plan_file.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {
namespace {

int RpcFailed(CommandContext& ctx, const grpc::Status& status, const char* call) {
  return ReportRpcError(ctx.err, status, call, ctx.client.options().address);
}

// After a verb: the session's new state in one line (or the reply as JSON).
int PrintVerbResult(CommandContext& ctx, const google::protobuf::Message& reply,
                    const v1::Session& session) {
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
  } else {
    ctx.out << "session " << session.session_id() << ": " << StateName(session.state()) << "\n";
    if (!session.state_reason().empty()) ctx.out << "  " << session.state_reason() << "\n";
    if (session.has_pending_prompt()) {
      ctx.out << "  waiting for the operator: step " << session.pending_prompt().step_index()
              << " (" << PromptKindName(session.pending_prompt().kind())
              << "): " << session.pending_prompt().text() << "\n";
    }
  }
  return kExitOk;
}

}  // namespace

int RunValidate(CommandContext& ctx, const std::string& plan_path, double time_scale) {
  Result<v1::Plan> plan = ReadPlanFile(plan_path);
  if (!plan.ok()) return ReportLocalError(ctx.err, plan.status());
  v1::ValidatePlanRequest request;
  *request.mutable_plan() = *plan;
  request.set_time_scale(time_scale);
  v1::ValidatePlanResponse reply;
  const grpc::Status status =
      ctx.client.control().ValidatePlan(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "ValidatePlan");
  // For a simulated rig, the same plan on a real one too (the daemon's waits do not scale).
  double real_rig_s = 0;
  if (time_scale != 1.0 && reply.valid() && !ctx.json) {
    request.set_time_scale(1);
    v1::ValidatePlanResponse real;
    const grpc::Status st =
        ctx.client.control().ValidatePlan(ctx.client.UnaryContext().get(), request, &real);
    if (!st.ok()) return RpcFailed(ctx, st, "ValidatePlan");
    real_rig_s = RigSeconds(real.summary());
  }
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
    return reply.valid() ? kExitOk : kExitInvalid;
  }
  if (reply.valid()) {
    ctx.out << plan_path << ": valid\n";
    if (reply.has_summary()) {
      if (plan->has_adaptive()) ctx.out << "  adaptive: the seed design,\n";
      ctx.out << "  " << PlanSummaryText(reply.summary(), time_scale, real_rig_s) << "\n";
      if (plan->has_adaptive()) {
        ctx.out << "  " << adaptive::AdaptiveBoundsText(*plan) << "\n";
      }
    } else {
      ctx.out << "  " << reply.step_count() << " steps, " << reply.operator_interventions()
              << " operator actions, about " << Duration(reply.estimated_duration_s()) << "\n";
    }
    return kExitOk;
  }
  const int n = reply.problems_size();
  ctx.out << plan_path << ": not valid, " << n << (n == 1 ? " problem" : " problems") << "\n";
  for (const v1::PlanProblem& p : reply.problems()) {
    ctx.out << "  " << (p.field_path().empty() ? "(plan)" : p.field_path()) << ": " << p.message()
            << "\n";
  }
  return kExitInvalid;
}

int RunSubmit(CommandContext& ctx, const std::string& plan_path, bool start_now, bool quiet) {
  Result<v1::Plan> plan = ReadPlanFile(plan_path);
  if (!plan.ok()) return ReportLocalError(ctx.err, plan.status());
  v1::SubmitPlanRequest request;
  *request.mutable_plan() = *plan;
  request.set_start_now(start_now);
  v1::SubmitPlanResponse reply;
  const grpc::Status status =
      ctx.client.control().SubmitPlan(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "SubmitPlan");
  const v1::Session& s = reply.session();
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
  } else if (quiet) {
    ctx.out << s.session_id() << "\n";
  } else {
    ctx.out << "submitted session " << s.session_id() << " \"" << s.name()
            << "\": " << StateName(s.state()) << "\n";
    if (s.has_summary()) ctx.out << "  " << PlanSummaryText(s.summary()) << "\n";
    // Started while another session holds the rig: which one, and that it starts by itself.
    if (s.state() == v1::SESSION_STATE_QUEUED && start_now && !s.state_reason().empty()) {
      ctx.out << "  " << s.state_reason() << "\n";
    }
    if (s.state() == v1::SESSION_STATE_QUEUED && !start_now) {
      ctx.out << "  start it: brdfctl start " << s.session_id() << "\n";
    }
    ctx.out << "  follow it: brdfctl watch " << s.session_id() << "\n";
  }
  return kExitOk;
}

int RunStart(CommandContext& ctx, const std::string& session_id) {
  v1::StartSessionRequest request;
  request.set_session_id(session_id);
  v1::StartSessionResponse reply;
  const grpc::Status status =
      ctx.client.control().StartSession(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "StartSession");
  return PrintVerbResult(ctx, reply, reply.session());
}

int RunPause(CommandContext& ctx, const std::string& session_id, bool immediate) {
  v1::PauseSessionRequest request;
  request.set_session_id(session_id);
  request.set_mode(immediate ? v1::PAUSE_MODE_IMMEDIATE : v1::PAUSE_MODE_DEFERRED);
  v1::PauseSessionResponse reply;
  const grpc::Status status =
      ctx.client.control().PauseSession(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "PauseSession");
  return PrintVerbResult(ctx, reply, reply.session());
}

int RunResume(CommandContext& ctx, const std::string& session_id) {
  v1::ResumeSessionRequest request;
  request.set_session_id(session_id);
  v1::ResumeSessionResponse reply;
  const grpc::Status status =
      ctx.client.control().ResumeSession(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "ResumeSession");
  return PrintVerbResult(ctx, reply, reply.session());
}

int RunAbort(CommandContext& ctx, const std::string& session_id, const std::string& reason) {
  v1::AbortSessionRequest request;
  request.set_session_id(session_id);
  request.set_reason(reason);
  v1::AbortSessionResponse reply;
  const grpc::Status status =
      ctx.client.control().AbortSession(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "AbortSession");
  return PrintVerbResult(ctx, reply, reply.session());
}

int RunAnswer(CommandContext& ctx, const std::string& session_id, int step_index,
              const std::string& note) {
  v1::AnswerPromptRequest request;
  request.set_session_id(session_id);
  request.set_step_index(step_index);
  request.set_note(note);
  v1::AnswerPromptResponse reply;
  const grpc::Status status =
      ctx.client.control().AnswerPrompt(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "AnswerPrompt");
  return PrintVerbResult(ctx, reply, reply.session());
}

int RunGet(CommandContext& ctx, const std::string& session_id) {
  v1::GetSessionRequest request;
  request.set_session_id(session_id);
  v1::Session reply;
  const grpc::Status status =
      ctx.client.control().GetSession(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "GetSession");
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
  } else {
    PrintSessionDetail(ctx.out, reply);
  }
  return kExitOk;
}

int RunEvents(CommandContext& ctx, const std::string& session_id) {
  v1::ListSessionEventsRequest request;
  request.set_session_id(session_id);
  v1::ListSessionEventsResponse reply;
  const grpc::Status status =
      ctx.client.control().ListSessionEvents(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "ListSessionEvents");
  for (const v1::SessionStateEvent& e : reply.events()) {
    if (ctx.json) {
      PrintJsonLine(ctx.out, e);
    } else {
      ctx.out << LocalTimeText(e.at()) << "  " << StateName(e.state());
      if (!e.reason().empty()) ctx.out << "  " << e.reason();
      ctx.out << "\n";
    }
  }
  return kExitOk;
}

int RunList(CommandContext& ctx, const std::vector<std::string>& states, unsigned limit,
            const ListFilters& filters) {
  v1::ListSessionsRequest request;
  request.set_rig(filters.rig);
  request.set_sample(filters.sample);
  request.set_material(filters.material);
  request.set_tag(filters.tag);
  for (const std::string& name : states) {
    v1::SessionState state{};
    if (!ParseStateName(name, &state)) {
      ctx.err << "brdfctl: --state " << name
              << " is not a session state; use queued, running, pausing, paused, "
                 "awaiting_operator, completed, aborted or failed\n";
      return kExitInvalid;
    }
    request.add_states(state);
  }
  // Every page, merged into one reply (and one JSON object).
  v1::ListSessionsResponse all;
  for (;;) {
    v1::ListSessionsResponse page;
    const grpc::Status status =
        ctx.client.control().ListSessions(ctx.client.UnaryContext().get(), request, &page);
    if (!status.ok()) return RpcFailed(ctx, status, "ListSessions");
    for (const v1::Session& s : page.sessions()) {
      if (limit > 0 && static_cast<unsigned>(all.sessions_size()) >= limit) break;
      *all.add_sessions() = s;
    }
    if (page.next_page_token().empty() ||
        (limit > 0 && static_cast<unsigned>(all.sessions_size()) >= limit)) {
      break;
    }
    request.set_page_token(page.next_page_token());
  }
  if (ctx.json) {
    PrintJsonLine(ctx.out, all);
    return kExitOk;
  }
  if (all.sessions().empty()) {
    const bool filtered = !states.empty() || !filters.rig.empty() || !filters.sample.empty() ||
                          !filters.material.empty() || !filters.tag.empty();
    ctx.out << "no sessions" << (filtered ? " match" : "") << "\n";
    return kExitOk;
  }
  for (const v1::Session& s : all.sessions()) ctx.out << SessionLine(s) << "\n";
  return kExitOk;
}

// "archive: caught up" / "archive: unreachable, 120 reading(s) behind (35.2 s) -- <why>".
void PrintArchiveStatus(std::ostream& out, const v1::ArchiveStatus& a) {
  static const char* const kWords[] = {"unknown",  "off",         "connecting", "caught up",
                                       "shipping", "unreachable", "refused"};
  const int state = static_cast<int>(a.state());
  out << "archive: " << (state >= 0 && state < 7 ? kWords[state] : "unknown");
  if (a.state() != v1::ARCHIVE_STATE_OFF) {
    out << ", " << a.lag_readings() << " reading(s) behind";
    if (a.lag_readings() > 0) out << " (" << Num(a.lag_seconds(), 3) << " s)";
    out << ", " << a.shipped_readings() << " shipped since start";
  }
  if (!a.detail().empty()) out << " -- " << a.detail();
  out << "\n";
}

int RunRig(CommandContext& ctx) {
  v1::GetRigStatusRequest request;
  v1::RigStatus reply;
  const grpc::Status status =
      ctx.client.control().GetRigStatus(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) return RpcFailed(ctx, status, "GetRigStatus");
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
    return kExitOk;
  }
  for (const v1::DeviceStatus& d : reply.devices()) {
    ctx.out << d.name() << ": " << ConnectionStateName(d.state()) << "  " << d.model() << " at "
            << d.address();
    if (!d.detail().empty()) ctx.out << "  (" << d.detail() << ")";
    ctx.out << "\n";
  }
  ctx.out << "meter serial: " << (reply.meter_serial().empty() ? "unknown" : reply.meter_serial())
          << "\n";
  ctx.out << "pose: "
          << (reply.live_pose_valid() ? PoseText(reply.live_pose()) : std::string("not known yet"))
          << "\n";
  ctx.out << "detector arm: "
          << (reply.detector_arm_motorized() ? "motorized" : "moved by the operator") << "\n";
  for (const v1::AxisStatus& a : reply.axes()) {
    if (!a.present()) continue;
    ctx.out << "  " << a.name() << ": " << Num(a.position_deg(), 6) << "°"
            << (a.moving() ? " moving" : "") << "  travel " << Num(a.min_deg()) << "…"
            << Num(a.max_deg()) << "°";
    if (a.alarm_code() != 0) ctx.out << "  ALARM " << a.alarm_code();
    ctx.out << "\n";
  }
  ctx.out << "active session: "
          << (reply.active_session_id().empty() ? "none" : reply.active_session_id()) << "\n";
  PrintArchiveStatus(ctx.out, reply.archive());
  return kExitOk;
}

// ---- The subcommands: their arguments and flags, and the Run function each calls. ----
namespace {

Runner AddValidateOptions(CLI::App& cmd) {
  struct Args {
    std::string plan_path;
    double time_scale = 1.0;
  };
  auto args = std::make_shared<Args>();
  cmd.add_option("plan", args->plan_path, "plan JSON file (- for standard input)")->required();
  cmd.add_option("--time-scale", args->time_scale,
                 "estimate for a simulated rig this many times faster (brdf-sim "
                 "--time-scale; the quick start's is 8)")
      ->check(CLI::Range(0.001, 1e6));
  return OnDaemon(
      [args](CommandContext& ctx) { return RunValidate(ctx, args->plan_path, args->time_scale); });
}

Runner AddSubmitOptions(CLI::App& cmd) {
  struct Args {
    std::string plan_path;
    bool start_now = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  cmd.add_option("plan", args->plan_path, "plan JSON file (- for standard input)")->required();
  cmd.add_flag("--start", args->start_now, "start it at once (else it stays queued)");
  cmd.add_flag("-q,--quiet", args->quiet, "print only the new session's id");
  return OnDaemon([args](CommandContext& ctx) {
    return RunSubmit(ctx, args->plan_path, args->start_now, args->quiet);
  });
}

// A subcommand whose only argument is the session id.
std::function<Runner(CLI::App&)> SessionIdOnly(int (*run)(CommandContext&, const std::string&)) {
  return [run](CLI::App& cmd) {
    auto session_id = std::make_shared<std::string>();
    AddSessionId(cmd, *session_id);
    return OnDaemon([run, session_id](CommandContext& ctx) { return run(ctx, *session_id); });
  };
}

Runner AddPauseOptions(CLI::App& cmd) {
  struct Args {
    std::string session_id;
    bool immediate = false;
  };
  auto args = std::make_shared<Args>();
  AddSessionId(cmd, args->session_id);
  cmd.add_flag("--immediate", args->immediate, "cancel the step in progress now");
  return OnDaemon(
      [args](CommandContext& ctx) { return RunPause(ctx, args->session_id, args->immediate); });
}

Runner AddAbortOptions(CLI::App& cmd) {
  struct Args {
    std::string session_id;
    std::string reason;
  };
  auto args = std::make_shared<Args>();
  AddSessionId(cmd, args->session_id);
  cmd.add_option("--reason", args->reason, "why (stored with the session)");
  return OnDaemon(
      [args](CommandContext& ctx) { return RunAbort(ctx, args->session_id, args->reason); });
}

Runner AddAnswerOptions(CLI::App& cmd) {
  struct Args {
    std::string session_id;
    int step_index = -1;
    std::string note;
  };
  auto args = std::make_shared<Args>();
  AddSessionId(cmd, args->session_id);
  cmd.add_option("step", args->step_index, "the prompt's step index (brdfctl get ID shows it)")
      ->required();
  cmd.add_option("--note", args->note, "remark stored with the session's log");
  return OnDaemon([args](CommandContext& ctx) {
    return RunAnswer(ctx, args->session_id, args->step_index, args->note);
  });
}

Runner AddListOptions(CLI::App& cmd) {
  struct Args {
    std::vector<std::string> states;
    unsigned limit = 0;
    ListFilters filters;
  };
  auto args = std::make_shared<Args>();
  cmd.add_option("--state", args->states,
                 "only these states: queued, running, pausing, paused, awaiting_operator, "
                 "completed, aborted, failed (repeat or comma-separate)")
      ->delimiter(',');
  cmd.add_option("--limit", args->limit, "at most this many (0: all)");
  cmd.add_option("--rig", args->filters.rig, "only sessions recorded by this rig ([rig] name)");
  cmd.add_option("--sample", args->filters.sample,
                 "only sessions of this sample: its id, or its name (ignoring case)");
  cmd.add_option("--material", args->filters.material,
                 "only sessions of samples of this material (ignoring case)");
  cmd.add_option("--tag", args->filters.tag, "only sessions of samples carrying this tag");
  return OnDaemon([args](CommandContext& ctx) {
    return RunList(ctx, args->states, args->limit, args->filters);
  });
}

Runner AddRigOptions(CLI::App&) {
  return OnDaemon([](CommandContext& ctx) { return RunRig(ctx); });
}

}  // namespace

void RegisterPlanCommands(CommandRegistry& registry) {
  registry.Add({"validate",
                "check a plan file against the rig: every problem with its field path, or the "
                "step count and duration",
                "", AddValidateOptions});
  registry.Add({"submit", "submit a plan file as a new session", "", AddSubmitOptions});
}

void RegisterOperatorCommands(CommandRegistry& registry) {
  registry.Add({"start", "start a queued session", "", SessionIdOnly(RunStart)});
  registry.Add({"pause",
                "pause a session after the current step (--immediate: cancel the step now; resume "
                "redoes it)",
                "", AddPauseOptions});
  registry.Add({"resume", "resume a paused session", "", SessionIdOnly(RunResume)});
  registry.Add({"abort", "stop a session for good (its readings are kept)", "", AddAbortOptions});
  registry.Add({"answer", "confirm the operator prompt at STEP once its manual action is done", "",
                AddAnswerOptions});
}

void RegisterViewCommands(CommandRegistry& registry) {
  registry.Add(
      {"get", "one session: state, progress, prompt, fault, plan", "", SessionIdOnly(RunGet)});
  registry.Add({"events", "a session's history of states, oldest first: time, state, reason", "",
                SessionIdOnly(RunEvents)});
  registry.Add({"list", "sessions, newest first", "", AddListOptions});
  registry.Add({"rig", "the rig: devices, axes, live pose, meter serial", "", AddRigOptions});
}

}  // namespace brdf::ctl
