#include "drivers/stage/modbus_errors.h"

#include <modbus.h>

#include <cerrno>

namespace brdf::drivers::stage {

int ModbusExceptionCode(int err) {
  if (err > MODBUS_ENOBASE && err < MODBUS_ENOBASE + MODBUS_EXCEPTION_MAX) {
    return err - MODBUS_ENOBASE;
  }
  return 0;
}

ModbusFailure ClassifyModbusErrno(int err) {
  switch (ModbusExceptionCode(err)) {
    case 0:
      break;
    case MODBUS_EXCEPTION_ILLEGAL_FUNCTION:
    case MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS:
    case MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE:
      return ModbusFailure::kIllegalRequest;
    case MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE:  // the AZ answers 04 while it cannot execute
    case MODBUS_EXCEPTION_SLAVE_OR_SERVER_BUSY:
      return ModbusFailure::kBusy;
    default:
      return ModbusFailure::kDeviceException;
  }
  switch (err) {
    case ETIMEDOUT:
      return ModbusFailure::kTimeout;
    case EMBBADCRC:
    case EMBBADDATA:
    case EMBBADEXC:
    case EMBUNKEXC:
    case EMBMDATA:
    case EMBBADSLAVE:
      return ModbusFailure::kStaleOrGarbled;
    case ECONNRESET:
    case ECONNREFUSED:
    case ECONNABORTED:
    case EPIPE:
    case ENOTCONN:
    case EBADF:
    case EIO:
    case ENXIO:
    case ENODEV:
    case ENOENT:
    case EHOSTUNREACH:
    case ENETUNREACH:
    case ENETDOWN:
      return ModbusFailure::kLinkDown;
    default:
      return ModbusFailure::kOther;
  }
}

std::string ModbusErrorText(int err) {
  const char* text = modbus_strerror(err);
  return text != nullptr ? text : "unknown error";
}

}  // namespace brdf::drivers::stage
