#include "tools/brdfctl/commands/rounds.h"

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/rounds_text.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {
namespace {

int RunRounds(CommandContext& ctx, const std::string& session_id) {
  v1::GetSessionRequest get;
  get.set_session_id(session_id);
  v1::Session session;
  grpc::Status status =
      ctx.client.control().GetSession(ctx.client.UnaryContext().get(), get, &session);
  if (!status.ok())
    return ReportRpcError(ctx.err, status, "GetSession", ctx.client.options().address);
  if (!session.plan().has_adaptive()) {
    ctx.err << "session " << session_id << " is not adaptive: only an adaptive plan has rounds "
            << "(docs/adaptive.md); `brdfctl get " << session_id << "` shows its plan\n";
    return kExitInvalid;
  }
  v1::ListAdaptiveRoundsRequest request;
  request.set_session_id(session_id);
  v1::ListAdaptiveRoundsResponse reply;
  status =
      ctx.client.control().ListAdaptiveRounds(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) {
    return ReportRpcError(ctx.err, status, "ListAdaptiveRounds", ctx.client.options().address);
  }
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
    return kExitOk;
  }
  for (const std::string& line : WrapText("session " + session.session_id() + " \"" +
                                          session.name() + "\": " + StateName(session.state()))) {
    ctx.out << line << "\n";
  }
  const std::vector<v1::AdaptiveRound> rounds(reply.rounds().begin(), reply.rounds().end());
  PrintRoundsTable(ctx.out, rounds, session.plan().adaptive());
  // The stop, as the session's reason once it completed ("adaptive: target reached; …").
  const std::string& reason = session.state_reason();
  if (reason.rfind("adaptive:", 0) == 0) {
    ctx.out << "\n";
    for (const std::string& line : WrapText("stopped: " + reason)) ctx.out << line << "\n";
  }
  return kExitOk;
}

}  // namespace

void RegisterRoundsCommand(CommandRegistry& registry) {
  registry.Add({"rounds",
                "an adaptive session's rounds: uncertainty left per round against the target, "
                "spend against the budgets, the last round's poses",
                "", [](CLI::App& cmd) {
                  auto session_id = std::make_shared<std::string>();
                  AddSessionId(cmd, *session_id);
                  return OnDaemon(
                      [session_id](CommandContext& ctx) { return RunRounds(ctx, *session_id); });
                }});
}

}  // namespace brdf::ctl
