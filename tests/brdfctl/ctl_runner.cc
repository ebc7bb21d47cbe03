#include "tests/brdfctl/ctl_runner.h"

#include <cstdlib>
#include <sstream>

namespace brdf::testing {

std::string SourceDir() {
#ifdef BRDF_TEST_SOURCE_DIR
  return BRDF_TEST_SOURCE_DIR;
#else
  const char* dir = std::getenv("BRDF_SOURCE_DIR");
  return dir != nullptr ? dir : ".";
#endif
}

Result<std::string> BrdfctlBinary() {
#ifdef BRDF_TEST_BUILD_DIR
  const char* fallback = BRDF_TEST_BUILD_DIR;
#else
  const char* fallback = nullptr;
#endif
  return BuiltProgram("brdfctl", "tools/brdfctl/brdfctl", "BRDFCTL_BINARY", fallback);
}

Result<CommandResult> RunBrdfctl(const std::vector<std::string>& args, const EnvVars& env,
                                 std::chrono::milliseconds timeout) {
  BRDF_ASSIGN_OR_RETURN(std::string binary, BrdfctlBinary());
  LaunchOptions options;
  options.args = args;
  options.stderr_to = LaunchOptions::Stderr::kPipe;
  options.stdin_from_null = true;
  options.unset_env = {"BRDF_ADDRESS", "BRDF_TOKEN"};
  options.set_env = env;
  CommandResult partial;
  Result<CommandResult> run = RunToCompletion("brdfctl", binary, options, timeout, &partial);
  if (run.status().code() == StatusCode::kTimeout) {
    return Timeout("brdfctl " + (args.empty() ? std::string() : args[0]) +
                   " did not finish within " + std::to_string(timeout.count()) +
                   " ms; it printed:\n" + partial.out + partial.err);
  }
  return run;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

}  // namespace brdf::testing
