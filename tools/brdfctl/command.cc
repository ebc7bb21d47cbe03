#include "tools/brdfctl/command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>
#include <utility>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {
namespace {

// The first line of a token file, without surrounding whitespace.
bool ReadTokenFile(const std::string& path, std::string* token) {
  std::ifstream in(path);
  if (!in) return false;
  std::getline(in, *token);
  const auto first = token->find_first_not_of(" \t\r\n");
  const auto last = token->find_last_not_of(" \t\r\n");
  *token = first == std::string::npos ? "" : token->substr(first, last - first + 1);
  return true;
}

}  // namespace

Runner OnDaemon(std::function<int(CommandContext& ctx)> run) {
  return [run = std::move(run)](const GlobalOptions& globals) {
    ClientOptions options = globals.client;
    if (!globals.token_file.empty() && !ReadTokenFile(globals.token_file, &options.token)) {
      std::cerr << "brdfctl: --token-file " << globals.token_file << ": cannot read it\n";
      return kExitInvalid;
    }
    options.timeout = std::chrono::milliseconds(static_cast<long long>(globals.timeout_s * 1000));
    Result<std::unique_ptr<Client>> client = Client::Create(options);
    if (!client.ok()) return ReportLocalError(std::cerr, client.status());
    CommandContext ctx{**client, globals.json, std::cout, std::cerr};
    return run(ctx);
  };
}

void AddSessionId(CLI::App& cmd, std::string& session_id) {
  cmd.add_option("id", session_id, "session id (brdfctl list)")->required();
}

}  // namespace brdf::ctl
