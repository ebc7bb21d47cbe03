// Runs the stage simulator alone so that tools/check/modbus_probe.py (or any Modbus client) can be
// pointed at it by hand:  stage_sim_runner [port] [time-scale]
// Prints "modbus-tcp 127.0.0.1:<port>", "modbus-rtu <pty>", "control-unit 100", then "ready", and
// serves until SIGINT or SIGTERM.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tools/brdf-sim/stage/simulator.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) {
  g_stop = 1;
}
}  // namespace

int main(int argc, char** argv) {
  brdf::sim::StageSimConfig config;
  config.tcp_port = argc > 1 ? std::atoi(argv[1]) : 0;
  config.time_scale.factor = argc > 2 ? std::atof(argv[2]) : 1.0;
  brdf::sim::SimControl control;
  brdf::sim::StageSimulator sim(config, control, [] { std::puts("power-cycle meter requested"); });
  std::string error;
  if (!sim.Start(&error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  std::printf("modbus-tcp 127.0.0.1:%d\nmodbus-rtu %s\ncontrol-unit %d\nready\n", sim.tcp_port(),
              sim.rtu_path().c_str(), sim.control_unit_id());
  std::fflush(stdout);
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  while (g_stop == 0) ::pause();
  sim.Shutdown();
  const brdf::Pose p = sim.LivePose();
  std::printf("final pose alpha=%.3f beta=%.3f gamma=%.3f delta=%.3f\n", p.alpha, p.beta, p.gamma,
              p.delta);
  return 0;
}
