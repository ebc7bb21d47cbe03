// What a failed libmodbus call means for the driver. libmodbus reports failures as -1 and errno:
// Modbus exception replies as MODBUS_ENOBASE + code, its own framing errors as EMB*, and system
// errors as plain errno values. The bus retries or gives up according to this classification.
#pragma once

#include <string>

namespace brdf::drivers::stage {

enum class ModbusFailure {
  kIllegalRequest,   // exception 01/02/03: the configured register map does not fit the drive
  kBusy,             // exception 04 (AZ: command execution disabled) or 06 (busy): retry later
  kDeviceException,  // any other exception (05, 0A/0B gateway, ...)
  kTimeout,          // no reply within the response timeout
  kStaleOrGarbled,   // a reply that does not belong to the request: late reply, CRC, wrong slave
  kLinkDown,         // the connection or port is gone
  kOther,            // anything else (a local error)
};

ModbusFailure ClassifyModbusErrno(int err);

// The Modbus exception code carried by `err`, or 0 when `err` is not an exception reply.
int ModbusExceptionCode(int err);

// modbus_strerror(err), never null.
std::string ModbusErrorText(int err);

}  // namespace brdf::drivers::stage
