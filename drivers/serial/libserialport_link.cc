#include "drivers/serial/libserialport_link.h"

#include <fcntl.h>
#include <libserialport.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "drivers/exclusive_open.h"
#include "drivers/serial/fd_io.h"

namespace brdf::drivers::serial {

namespace {

// libserialport's last error text, freed properly.
std::string LastErrorMessage() {
  char* message = sp_last_error_message();
  std::string text = message ? message : "unknown error";
  sp_free_error_message(message);
  return text;
}

}  // namespace

LibSerialPortLink::LibSerialPortLink(SerialSettings settings, LogSink log)
    : settings_(std::move(settings)), log_(std::move(log)) {}

LibSerialPortLink::~LibSerialPortLink() {
  Close();
}

Status LibSerialPortLink::NotOpen() const {
  return FailedPrecondition("serial port " + settings_.port + " is not open: connect first");
}

Status LibSerialPortLink::Open(bool seen_before) {
  Close();
  const std::string& name = settings_.port;
  // libserialport 0.1.1 only knows ports by their /dev/ttyXXX name (it looks them up under
  // /sys/class/tty), so links such as /dev/serial/by-id/... are resolved first.
  char resolved[PATH_MAX];
  if (::realpath(name.c_str(), resolved) == nullptr) return OpenError(errno, name, seen_before);
  sp_port* port = nullptr;
  errno = 0;
  if (sp_get_port_by_name(resolved, &port) != SP_OK) {
    const int err = sp_last_error_code();
    if (err != 0) return OpenError(err, name, seen_before);
    return ConfigurationError("libserialport does not recognise " + name +
                              " as a serial port: check the port name in the configuration "
                              "(ls /dev/ttyUSB* /dev/serial/by-id)");
  }
  if (sp_open(port, SP_MODE_READ_WRITE) != SP_OK) {
    const int err = sp_last_error_code();
    const std::string why = LastErrorMessage();
    sp_free_port(port);
    if (err == ENOTTY || err == EINVAL) {
      return ConfigurationError("cannot open " + name + " as a serial port (" + why +
                                "): check the port name in the configuration");
    }
    return OpenError(err, name, seen_before);
  }
  const bool configured =
      sp_set_baudrate(port, settings_.baud) == SP_OK && sp_set_bits(port, 8) == SP_OK &&
      sp_set_parity(port, SP_PARITY_NONE) == SP_OK && sp_set_stopbits(port, 1) == SP_OK &&
      sp_set_flowcontrol(port, settings_.hardware_flow_control ? SP_FLOWCONTROL_RTSCTS
                                                               : SP_FLOWCONTROL_NONE) == SP_OK;
  int fd = -1;
  if (!configured || sp_get_port_handle(port, &fd) != SP_OK || fd < 0) {
    const std::string why = LastErrorMessage();
    sp_close(port);
    sp_free_port(port);
    return ConfigurationError("cannot set " + name + " to " + std::to_string(settings_.baud) +
                              " baud 8N1 (" + why + "): check that it is a serial port");
  }
  // One owner: a port another brdfd (or any program holding its lock) uses is refused, naming it.
  if (Status owned = LockDeviceExclusively(fd, name); !owned.ok()) {
    sp_close(port);
    sp_free_port(port);
    return owned;
  }
  // The waits in fd_io poll the handle and expect reads and writes never to block.
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  port_ = port;
  fd_ = fd;
  return Status::Ok();
}

void LibSerialPortLink::Close() {
  if (port_ != nullptr) {
    sp_close(port_);
    sp_free_port(port_);
  }
  port_ = nullptr;
  fd_ = -1;
}

Status LibSerialPortLink::Write(std::string_view bytes, const CallContext& ctx) {
  if (port_ == nullptr) return NotOpen();
  return WriteAll(fd_, settings_.port, bytes, ctx);
}

Result<std::string> LibSerialPortLink::Read(TimePoint until, const CallContext& ctx) {
  if (port_ == nullptr) return NotOpen();
  return ReadAvailable(fd_, settings_.port, until, ctx);
}

Status LibSerialPortLink::FlushInput() {
  if (port_ == nullptr) return NotOpen();
  if (sp_flush(port_, SP_BUF_INPUT) != SP_OK) {
    return VanishedError(settings_.port, "flushing input", sp_last_error_code());
  }
  return Status::Ok();
}

Status LibSerialPortLink::SetRts(bool on) {
  if (port_ == nullptr) return NotOpen();
  if (sp_set_rts(port_, on ? SP_RTS_ON : SP_RTS_OFF) != SP_OK) {
    const int err = sp_last_error_code();
    if (err != ENOTTY && err != EINVAL) return VanishedError(settings_.port, "setting RTS", err);
    if (log_) {
      log_("serial port " + settings_.port + ": " + (on ? "raising" : "dropping") +
           " RTS not supported (" + LastErrorMessage() + "); carrying on");
    }
  }
  return Status::Ok();
}

}  // namespace brdf::drivers::serial
