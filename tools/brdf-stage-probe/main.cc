// brdf-stage-probe: checks the stage's drives against a register profile before a session.
//
//   brdf-stage-probe --config /etc/brdfd/brdfd.toml        # the daemon's [stage] as configured
//   brdf-stage-probe --tcp 192.168.1.50:502 --profile az --unit 1 --unit 2
//   brdf-stage-probe --rtu /dev/ttyUSB1 --baud 115200 --parity E --profile-file lab.toml
//
// Reads only (FC03). Exit status: 0 every unit answered and fits the profile, 1 a mismatch or a
// unit that does not answer (the report says what to set), 2 bad arguments, a profile that does
// not load or a bus that cannot be opened.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "daemon/config/config.h"
#include "drivers/stage/profile_file.h"
#include "tools/brdf-stage-probe/stage_probe.h"

namespace {

using brdf::Result;
using brdf::Status;
namespace stage = brdf::drivers::stage;
namespace probe = brdf::tools::stage_probe;

struct Args {
  std::string config;
  std::string tcp;
  std::string rtu;
  int baud = 115200;
  std::string parity = "E";
  std::string profile;
  std::string profile_file;
  std::vector<int> units;
  double counts_per_degree = 0;
  int timeout_ms = 500;
};

int Fail(const std::string& message) {
  std::cerr << "brdf-stage-probe: " << message << "\n";
  return 2;
}

// Fills the options from brdfd.toml's [stage] (transport, address, profile, axes' unit ids).
Status FromConfig(const std::string& path, probe::ProbeOptions& o, std::string& profile,
                  std::string& profile_file) {
  BRDF_ASSIGN_OR_RETURN(brdf::daemon::Config config, brdf::daemon::LoadConfig(path));
  const brdf::daemon::StageConfig& s = config.stage;
  if (s.transport == "rtu") {
    o.bus.endpoint = stage::RtuEndpoint{s.device, s.baud, s.parity, 8, 1};
  } else {
    o.bus.endpoint = stage::TcpEndpoint{s.host, s.port};
  }
  o.bus.response_timeout = std::chrono::milliseconds(s.response_timeout_ms);
  profile = s.profile;
  profile_file = s.profile_file;
  o.unit_ids.clear();
  for (const auto* a : {&s.alpha, &s.beta, &s.gamma, &s.delta}) {
    if (a->present) o.unit_ids.push_back(a->unit_id);
  }
  o.counts_per_degree = s.alpha.counts_per_degree;
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  CLI::App app{
      "Reads the stage drives' status, alarm and position with a register profile and "
      "reports what does not fit it (word order, alarms, readiness). Reads only."};
  app.add_option("--config", args.config, "brdfd.toml: take [stage] from it");
  app.add_option("--tcp", args.tcp, "Modbus TCP host:port");
  app.add_option("--rtu", args.rtu, "Modbus RTU serial device");
  app.add_option("--baud", args.baud, "RTU baud rate")->capture_default_str();
  app.add_option("--parity", args.parity, "RTU parity N, E or O")->capture_default_str();
  app.add_option("--profile", args.profile, "built-in profile: az, leadshine, moons");
  app.add_option("--profile-file", args.profile_file, "a profile file");
  app.add_option("--unit", args.units, "unit id of an axis (repeat; default 1 and 2)");
  app.add_option("--counts-per-degree", args.counts_per_degree, "for the report (default 27.78)");
  app.add_option("--timeout-ms", args.timeout_ms, "reply timeout")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  probe::ProbeOptions o;
  o.bus.response_timeout = std::chrono::milliseconds(args.timeout_ms);
  o.bus.busy_window = std::chrono::milliseconds(1000);
  std::string profile = "az";
  std::string profile_file;
  if (!args.config.empty()) {
    if (Status st = FromConfig(args.config, o, profile, profile_file); !st.ok()) {
      return Fail(st.message());
    }
  }
  if (!args.tcp.empty() && !args.rtu.empty()) return Fail("give --tcp or --rtu, not both");
  if (!args.tcp.empty()) {
    const auto colon = args.tcp.rfind(':');
    int port = 0;
    if (colon == std::string::npos || std::sscanf(args.tcp.c_str() + colon + 1, "%d", &port) != 1 ||
        port < 1 || port > 65535) {
      return Fail("--tcp " + args.tcp + ": give host:port, e.g. 192.168.1.50:502");
    }
    o.bus.endpoint = stage::TcpEndpoint{args.tcp.substr(0, colon), port};
  } else if (!args.rtu.empty()) {
    if (args.parity.size() != 1) return Fail("--parity must be N, E or O");
    o.bus.endpoint = stage::RtuEndpoint{args.rtu, args.baud, args.parity[0], 8, 1};
  } else if (args.config.empty()) {
    return Fail("give the bus: --tcp host:port, --rtu /dev/ttyUSB1 or --config brdfd.toml");
  }
  if (!args.profile.empty() && !args.profile_file.empty()) {
    return Fail("give --profile or --profile-file, not both");
  }
  if (!args.profile.empty()) {
    profile = args.profile;
    profile_file.clear();
  }
  if (!args.profile_file.empty()) profile_file = args.profile_file;
  Result<stage::RegisterProfile> loaded =
      profile_file.empty() ? stage::BuiltinProfile(profile) : stage::LoadProfileFile(profile_file);
  if (!loaded.ok()) return Fail(loaded.status().message());
  o.profile = std::move(loaded).value();
  o.profile_label = profile_file.empty() ? "built-in " + profile : "file " + profile_file;
  if (!args.units.empty()) o.unit_ids = args.units;
  if (args.counts_per_degree > 0) o.counts_per_degree = args.counts_per_degree;

  const auto ctx = brdf::CallContext::WithTimeout(std::chrono::seconds(30));
  Result<probe::ProbeReport> report = probe::ProbeStage(o, ctx);
  if (!report.ok()) return Fail(report.status().message());
  std::cout << probe::FormatReport(*report, o);
  return report->ok() ? 0 : 1;
}
