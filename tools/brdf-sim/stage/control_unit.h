// The control unit id of the simulated stage bus: holding registers that read and write
// SimControl (mounted target, serial and Modbus faults) and a register that power-cycles the
// meter. The register map is documented in stage/control_map.h.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "tools/brdf-sim/sim_shared.h"
#include "tools/brdf-sim/stage/pdu.h"

namespace brdf::sim {

class StageControlUnit final : public RegisterUnit {
 public:
  // `power_cycle_meter` may be empty (the write is then accepted and does nothing).
  StageControlUnit(SimControl& control, std::function<void()> power_cycle_meter);

  std::uint8_t ReadRegisters(std::uint16_t address, std::uint16_t count,
                             std::vector<std::uint16_t>& out) override;
  std::uint8_t WriteRegisters(std::uint16_t address,
                              std::span<const std::uint16_t> values) override;

 private:
  SimControl& control_;
  std::function<void()> power_cycle_meter_;
};

}  // namespace brdf::sim
