// tools/check/pr650_probe.py (the manual serial client) against the simulated meter: it must get
// and show the exact reply bytes. Skipped where Debian's python3-serial is missing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "tests/drivers_pr650/pr650_test_rig.h"

namespace brdf::testing {
namespace {

using ::testing::HasSubstr;

struct CommandRun {
  int exit_code = -1;
  std::string out;
};

CommandRun RunCommand(const std::string& command) {
  CommandRun run;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) run.out.append(buffer, n);
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

TEST(Pr650Probe, ShowsTheExactReplyBytes) {
  if (RunCommand("/usr/bin/python3 -c 'import serial'").exit_code != 0) {
    GTEST_SKIP() << "/usr/bin/python3 without python3-serial";
  }
  // $BRDF_SOURCE_DIR wins (a moved tree); else the script of the tree this test was built from.
  const char* source = std::getenv("BRDF_SOURCE_DIR");
  const std::string probe = source != nullptr ? std::string(source) + "/tools/check/pr650_probe.py"
                                              : std::string(BRDF_PR650_PROBE_SCRIPT);

  FakeMeterBackend backend;
  sim::SimControl control;
  sim::Pr650Endpoint endpoint(backend, control, FastEndpointOptions());
  ASSERT_TRUE(endpoint.Start().ok());

  CommandRun run = RunCommand("/usr/bin/python3 " + probe + " " + endpoint.path() +
                              " --settle 0.01 --pacing 0.01 --short-timeout 1 --long-timeout 5"
                              " --commands B3 d120 M0 D5");
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_THAT(run.out, HasSubstr("> 'B3': 5 bytes"));
  EXPECT_THAT(run.out, HasSubstr("b'000\\r\\n'"));
  EXPECT_THAT(run.out, HasSubstr("b'0101,008.0,0380.,0780.,004.\\r\\n'"));
  EXPECT_THAT(run.out, HasSubstr("> 'D5': 1734 bytes"));
  EXPECT_THAT(run.out, HasSubstr("b'0380.,1.230E-02\\r\\n'"));
  EXPECT_THAT(run.out, HasSubstr("RTS not supported"));

  control.set_serial({.silent = true});
  run = RunCommand("/usr/bin/python3 " + probe + " " + endpoint.path() +
                   " --no-wake --short-timeout 0.2 --commands B3");
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_THAT(run.out, HasSubstr("no reply"));
}

}  // namespace
}  // namespace brdf::testing
