#include "drivers/serial/serial_link.h"

#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <climits>
#include <cstdlib>

#include "drivers/serial/libserialport_link.h"
#include "drivers/serial/termios_link.h"

namespace brdf::drivers::serial {

bool IsSupportedBaud(int baud) {
  switch (baud) {
    case 1200:
    case 2400:
    case 4800:
    case 9600:
    case 19200:
    case 38400:
    case 57600:
    case 115200:
      return true;
    default:
      return false;
  }
}

bool IsPseudoTerminal(const std::string& port) {
  char resolved[PATH_MAX];
  if (::realpath(port.c_str(), resolved) == nullptr) return false;
  const std::string target = resolved;
  if (target.rfind("/dev/pts/", 0) == 0) return true;
  // Unix98 pty slaves use character majors 136–143 wherever devpts is mounted.
  struct stat st {};
  if (::stat(resolved, &st) != 0 || !S_ISCHR(st.st_mode)) return false;
  const unsigned int major_number = major(st.st_rdev);
  return major_number >= 136 && major_number <= 143;
}

Result<std::unique_ptr<SerialLink>> MakeSerialLink(const SerialSettings& settings, LogSink log) {
  if (settings.port.empty()) {
    return ConfigurationError(settings.device +
                              " serial port name is empty: set it in the configuration "
                              "(e.g. /dev/ttyUSB0)");
  }
  if (settings.port.find('\0') != std::string::npos) {
    return ConfigurationError(settings.device +
                              " serial port name contains a NUL byte: fix the configuration");
  }
  if (!IsSupportedBaud(settings.baud)) {
    return ConfigurationError(settings.device + " baud rate " + std::to_string(settings.baud) +
                              " is not supported: use a standard rate 1200–115200 that the "
                              "meter is set to");
  }
  if (IsPseudoTerminal(settings.port)) {
    return std::unique_ptr<SerialLink>(std::make_unique<TermiosLink>(settings, std::move(log)));
  }
  return std::unique_ptr<SerialLink>(std::make_unique<LibSerialPortLink>(settings, std::move(log)));
}

}  // namespace brdf::drivers::serial
