// brdfctl's subcommands as data: each family of subcommands (commands/control.h, commands/watch.h,
// …) registers its own into a CommandRegistry — name, help, its CLI11 arguments and flags, and
// what runs it — and main.cc only parses the shared flags, finds the subcommand given and runs it.
// The registry keeps the order of registration, which is the order `brdfctl --help` lists them
// (command_list.cc).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "tools/brdfctl/client.h"
#include "tools/brdfctl/command_context.h"

namespace CLI {
class App;
}

namespace brdf::ctl {

// The flags every subcommand shares, given before or after its name (main.cc declares them):
// how to reach brdfd, and --json.
struct GlobalOptions {
  ClientOptions client;    // --address, --token, --tls, --ca, --cert, --key
  std::string token_file;  // --token-file: the token is this file's first line
  double timeout_s = 10;   // --timeout, seconds (ClientOptions::timeout once connected)
  bool json = false;       // --json
};

// Runs a parsed subcommand and returns its exit status (exit_codes.h). Results go to standard
// output, errors and notes to standard error.
using Runner = std::function<int(const GlobalOptions& globals)>;

struct Command {
  std::string name;   // "watch"
  std::string help;   // one line for `brdfctl --help`
  std::string group;  // the --help heading; empty: "Subcommands"
  // Declares the subcommand's arguments and flags on `cmd` and returns the Runner that reads
  // what CLI11 parsed into them (the Runner owns that storage).
  std::function<Runner(CLI::App& cmd)> add_options;
};

class CommandRegistry {
 public:
  void Add(Command command) { commands_.push_back(std::move(command)); }
  // In the order added.
  const std::vector<Command>& commands() const { return commands_; }

 private:
  std::vector<Command> commands_;
};

// Every subcommand of brdfctl, in --help order (command_list.cc).
CommandRegistry BrdfctlCommands();

// A Runner for a subcommand that talks to brdfd: reads --token-file (exit 2 when it cannot),
// builds the client (a local error when a TLS file cannot be read) and runs `run` with it, writing
// to standard output and standard error.
Runner OnDaemon(std::function<int(CommandContext& ctx)> run);

// The session id every per-session subcommand takes first: "id", required.
void AddSessionId(CLI::App& cmd, std::string& session_id);

}  // namespace brdf::ctl
