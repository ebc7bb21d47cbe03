// Runs the built brdfctl as a child process (tests/support/process_launcher.h), the way a user or a
// script does: arguments, extra environment variables, standard input closed; returns its exit code
// and everything it printed.
//
// The binary is $BRDF_BUILD_DIR/tools/brdfctl/brdfctl (brdf_add_test sets BRDF_BUILD_DIR);
// $BRDFCTL_BINARY overrides the path.
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "core/status.h"
#include "tests/support/process_launcher.h"

namespace brdf::testing {

Result<std::string> BrdfctlBinary();

// The repository's root (compiled in; $BRDF_SOURCE_DIR otherwise), for examples/plans/.
std::string SourceDir();

// Runs brdfctl to completion within `timeout` (then kills it and returns kTimeout). `env` is set
// for the child on top of the test's own environment; BRDF_ADDRESS and BRDF_TOKEN are removed
// first, so a test only sees what it passes.
Result<CommandResult> RunBrdfctl(const std::vector<std::string>& args, const EnvVars& env = {},
                                 std::chrono::milliseconds timeout = std::chrono::seconds(30));

// The lines of `text` (without the newlines; no trailing empty line).
std::vector<std::string> Lines(const std::string& text);

}  // namespace brdf::testing
