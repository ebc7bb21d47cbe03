// brdfctl: the command line for brdfd. Every API call is a subcommand (README.md):
//   brdfctl validate|submit PLAN.json, start|pause|resume|abort|get|watch|readings ID,
//   answer ID STEP, list, rig, interpolate ID --theta-i A --theta-o B --phi C,
//   export ID csv|grid|merl|rgl [-o FILE], appearance ID [--illuminant D65|A] [-o FILE.ppm]
// plus `sim-mount` for the simulated rig only. Address and token from --address/--token or
// BRDF_ADDRESS/BRDF_TOKEN. Exit status: exit_codes.h.
// Each subcommand is declared by its own file (command.h, command_list.cc); this file parses the
// flags they share, finds the subcommand given and runs it.
#include <CLI/CLI.hpp>
#include <iostream>
#include <utility>
#include <vector>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/exit_codes.h"

namespace {

using namespace brdf::ctl;

constexpr const char* kFooter = R"(
Environment: BRDF_ADDRESS (default 127.0.0.1:50051), BRDF_TOKEN (the bearer token; --token-file
reads it from a file instead). Flags override the environment.
Output is readable by default; --json prints each reply as protobuf JSON, one object per line.
Exit status: 0 done, 1 failure (daemon unreachable, other errors), 2 invalid argument (bad plan,
bad flag), 3 authentication (no, wrong or too weak a token), 4 no result (watch: the session
ended aborted or failed; interpolate: no spectrum at that direction).)";

void AddGlobalOptions(CLI::App& app, GlobalOptions& g) {
  app.add_option("--address", g.client.address, "brdfd's host:port (or unix:/path)")
      ->envname("BRDF_ADDRESS")
      ->capture_default_str();
  app.add_option("--token", g.client.token, "bearer token (operator or analyst)")
      ->envname("BRDF_TOKEN");
  app.add_option("--token-file", g.token_file, "read the bearer token from this file's first line");
  app.add_flag("--tls", g.client.tls, "connect with TLS");
  app.add_option("--ca", g.client.ca_file, "TLS: PEM roots to trust (default: the system's)");
  app.add_option("--cert", g.client.cert_file, "TLS: client certificate (mutual TLS)");
  app.add_option("--key", g.client.key_file, "TLS: client private key (mutual TLS)");
  app.add_option("--timeout", g.timeout_s, "seconds to wait for each call (streams excepted)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--json", g.json, "print replies as protobuf JSON, one object per line");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"brdfctl: control brdfd (spectral BRDF measurement daemon) and query its data"};
  app.footer(kFooter);
  app.require_subcommand(1);
  app.fallthrough();  // global flags may come after the subcommand too
  GlobalOptions globals;
  AddGlobalOptions(app, globals);

  const CommandRegistry registry = BrdfctlCommands();
  std::vector<std::pair<CLI::App*, Runner>> subcommands;
  for (const Command& command : registry.commands()) {
    CLI::App* cmd = app.add_subcommand(command.name, command.help);
    if (!command.group.empty()) cmd->group(command.group);
    subcommands.emplace_back(cmd, command.add_options(*cmd));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and friends are "errors" with exit code 0; usage errors exit 2 (a bad argument).
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitInvalid;
  }
  for (const auto& [cmd, run] : subcommands) {
    if (cmd->parsed()) return run(globals);
  }
  std::cerr << app.help();
  return kExitInvalid;
}
