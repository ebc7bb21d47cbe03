// Acts as the operator on a running brdf-sim: writes the control unit's holding registers (what is
// mounted in front of the meter, the meter's power, injected faults) over Modbus TCP, using the
// register map in tools/brdf-sim/stage/control_map.h. Also reads an axis' feedback position, so a
// test can see where the simulated stage is without a stage driver.
//
// One instance, one connection, one thread at a time (a libmodbus context is not thread-safe).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"
#include "tools/brdf-sim/sim_shared.h"

typedef struct _modbus modbus_t;

namespace brdf::testing {

class ModbusControl {
 public:
  // Connects to brdf-sim's Modbus TCP server; `unit` is the control unit id it printed.
  static Result<std::unique_ptr<ModbusControl>> Connect(
      const std::string& host, int port, int unit = 100,
      std::chrono::milliseconds response_timeout = std::chrono::seconds(2));
  ~ModbusControl();
  ModbusControl(const ModbusControl&) = delete;
  ModbusControl& operator=(const ModbusControl&) = delete;

  Status SetMounted(sim::MountedTarget target);
  Result<sim::MountedTarget> Mounted();
  // Switches the simulated PR-650 off and on (it leaves remote mode; the wake window restarts).
  Status PowerCycleMeter();

  // Writes every serial (or Modbus) fault register at once; fields left at their defaults clear
  // the corresponding fault.
  Status SetSerialFaults(const sim::SerialFaults& faults);
  Status SetModbusFaults(const sim::ModbusFaults& faults);
  // Reads them back ("next N" counters read how many are left).
  Result<sim::SerialFaults> SerialFaults();
  Result<sim::ModbusFaults> ModbusFaults();

  // The feedback position of an axis unit (1 α … 4 δ) in counts, and in degrees with the
  // simulator's default scale (10,000 counts per revolution, zero at 0 counts).
  Result<std::int32_t> AxisCounts(int axis_unit);
  Result<double> AxisDegrees(int axis_unit, double counts_per_degree = 10000.0 / 360.0);

  // Raw access to the control unit.
  Status WriteRegisters(std::uint16_t address, std::span<const std::uint16_t> values);
  Result<std::vector<std::uint16_t>> ReadRegisters(std::uint16_t address, int count);

 private:
  ModbusControl(modbus_t* ctx, int unit, std::string where);
  Status Error(const std::string& what) const;
  Result<std::vector<std::uint16_t>> ReadFrom(int unit, std::uint16_t address, int count);

  modbus_t* ctx_;
  int unit_;
  std::string where_;  // "127.0.0.1:1502 unit 100", for messages
};

}  // namespace brdf::testing
