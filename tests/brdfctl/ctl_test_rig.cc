#include "tests/brdfctl/ctl_test_rig.h"

#include <fstream>
#include <sstream>
#include <thread>

#include "tests/support/sim/rig.h"

namespace brdf::testing {

using namespace std::chrono_literals;

CtlRig::CtlRig() : dir_("brdfctl-test") {}

CtlRig::~CtlRig() {
  daemon_.reset();  // first: it must not see its devices vanish under a session
  sim_control_.reset();
  sim_.reset();
}

std::string CtlRig::modbus() const {
  return sim_->modbus_host() + ":" + std::to_string(sim_->modbus_port());
}

Status CtlRig::Start() {
  if (dir_.path().empty()) return IoError("no temporary directory: " + dir_.error());
  BRDF_ASSIGN_OR_RETURN(SimRig sim, StartSimRig(/*seed=*/3));
  sim_ = std::move(sim.sim);
  sim_control_ = std::move(sim.control);

  // Like deploy/quickstart.sh's configuration, with the meter's timings shortened for 50×.
  std::ostringstream toml;
  toml << "[server]\nlisten = \"127.0.0.1:0\"\n"
       << "[storage]\ndatabase = \"" << dir_.file("brdfd.db").string() << "\"\n"
       << "[meter]\nport = \"" << sim_->pr650_path() << "\"\n"
       << "pacing_ms = 5\nquiet_gap_ms = 20\nreply_timeout_ms = 1000\n"
       << "measurement_timeout_ms = 5000\nwake_attempts = 3\nrts_settle_ms = 20\n"
       // brdf-sim's meter, for the estimates (docs/pr650.md, "How long a reading takes").
       << "overhead_ms = 1000\nadaptive_reference_ms = 150\n"
       << "adaptive_dark_ms = 6000\nadaptive_sample_ms = 650\n"
       << "[meter.quality]\n\"10\" = \"accept_and_flag\"\n"
       << "[stage]\ntransport = \"tcp\"\naddress = \"" << modbus() << "\"\n"
       << "response_timeout_ms = 300\ndetector_arm_motorized = true\n"
       << "[stage.axes.delta]\npresent = true\n"
       // The simulator's speed-up, for the estimates and ETAs (as quickstart.sh writes it).
       << "[rig]\ntime_scale = " << kSimTimeScale << "\n"
       << "[[auth.tokens]]\nname = \"ctl-operator\"\ntoken = \"" << kCtlOperatorToken
       << "\"\nrole = \"operator\"\n"
       << "[[auth.tokens]]\nname = \"ctl-analyst\"\ntoken = \"" << kCtlAnalystToken
       << "\"\nrole = \"analyst\"\n"
       << "[log]\nlevel = \"info\"\n";
  const std::string config = dir_.file("brdfd.toml").string();
  {
    std::ofstream out(config);
    out << toml.str();
    if (!out) return IoError("cannot write " + config);
  }
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<DaemonProcess> daemon,
                        DaemonProcess::Start({"--config", config, "--shutdown-timeout", "5"},
                                             dir_.file("brdfd.log").string()));
  daemon_ = std::move(daemon);

  // The devices connect in the background.
  const auto until = std::chrono::steady_clock::now() + 15s;
  std::string last;
  while (std::chrono::steady_clock::now() < until) {
    Result<CommandResult> rig = Ctl({"rig"});
    if (rig.ok()) {
      last = rig->out + rig->err;
      if (last.find("meter: connected") != std::string::npos &&
          last.find("stage: connected") != std::string::npos) {
        return Status::Ok();
      }
    }
    std::this_thread::sleep_for(100ms);
  }
  return Timeout("the rig did not connect within 15 s; brdfctl rig said:\n" + last +
                 "\nbrdfd's log:\n" + log());
}

std::string CtlRig::log() const {
  return daemon_ ? daemon_->log() : std::string("(no daemon)");
}

EnvVars CtlRig::Env(const std::string& token) const {
  return {{"BRDF_ADDRESS", address()}, {"BRDF_TOKEN", token}};
}

Result<CommandResult> CtlRig::Ctl(const std::vector<std::string>& args, const std::string& token,
                                  std::chrono::milliseconds timeout) const {
  return RunBrdfctl(args, Env(token), timeout);
}

}  // namespace brdf::testing
