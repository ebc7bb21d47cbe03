#include "tests/support/sim/rig.h"

namespace brdf::testing {

std::vector<std::string> FastSimArgs(int seed, const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"--time-scale",  std::to_string(kSimTimeScale),
                                   "--seed",        std::to_string(seed),
                                   "--modbus-port", "0",
                                   "--wake-window", "0",
                                   "--no-pacing",   "--log-level",
                                   "warn"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::string SimRig::modbus_address() const {
  return sim->modbus_host() + ":" + std::to_string(sim->modbus_port());
}

Result<SimRig> StartSimRig(int seed, const std::vector<std::string>& extra) {
  SimRig rig;
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<SimProcess> sim,
                        SimProcess::Start(FastSimArgs(seed, extra)));
  rig.sim = std::move(sim);
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<ModbusControl> control,
                        ModbusControl::Connect(rig.sim->modbus_host(), rig.sim->modbus_port(),
                                               rig.sim->control_unit()));
  rig.control = std::move(control);
  return rig;
}

}  // namespace brdf::testing
