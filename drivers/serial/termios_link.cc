#include "drivers/serial/termios_link.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "drivers/exclusive_open.h"
#include "drivers/serial/fd_io.h"

namespace brdf::drivers::serial {

namespace {

speed_t SpeedFor(int baud) {
  switch (baud) {
    case 1200:
      return B1200;
    case 2400:
      return B2400;
    case 4800:
      return B4800;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    default:
      return B9600;
  }
}

// What a pty (or another device without the feature) answers to a terminal call it lacks.
bool IsUnsupported(int err) {
  return err == ENOTTY || err == EINVAL;
}

}  // namespace

TermiosLink::TermiosLink(SerialSettings settings, LogSink log)
    : settings_(std::move(settings)), log_(std::move(log)) {}

TermiosLink::~TermiosLink() {
  Close();
}

void TermiosLink::Tolerate(std::string_view what, int err) {
  if (!log_) return;
  log_("serial port " + settings_.port + ": " + std::string(what) + " not supported (" +
       std::strerror(err) + "); normal on a pseudo-terminal, carrying on");
}

Status TermiosLink::NotOpen() const {
  return FailedPrecondition("serial port " + settings_.port + " is not open: connect first");
}

Status TermiosLink::Open(bool seen_before) {
  Close();
  const int fd = ::open(settings_.port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return OpenError(errno, settings_.port, seen_before);
  if (!::isatty(fd)) {
    ::close(fd);
    return ConfigurationError("serial port " + settings_.port +
                              " is not a terminal device: check the port name in the "
                              "configuration");
  }
  // One owner: a port another brdfd (or any program holding its lock) uses is refused, naming it.
  if (Status owned = LockDeviceExclusively(fd, settings_.port); !owned.ok()) {
    ::close(fd);
    return owned;
  }
  termios t{};
  if (::tcgetattr(fd, &t) != 0) {
    const int err = errno;
    if (!IsUnsupported(err)) {
      ::close(fd);
      return OpenError(err, settings_.port, seen_before);
    }
    fd_ = fd;
    Tolerate("reading the line settings (tcgetattr)", err);
    return Status::Ok();
  }
  // Raw bytes both ways: no echo, no line editing, no CR/LF translation, no XON/XOFF.
  ::cfmakeraw(&t);
  t.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS);
  t.c_cflag |= CS8 | CLOCAL | CREAD;
  if (settings_.hardware_flow_control) t.c_cflag |= CRTSCTS;
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  ::cfsetispeed(&t, SpeedFor(settings_.baud));
  ::cfsetospeed(&t, SpeedFor(settings_.baud));
  if (::tcsetattr(fd, TCSANOW, &t) != 0) {
    const int err = errno;
    if (!IsUnsupported(err)) {
      ::close(fd);
      return OpenError(err, settings_.port, seen_before);
    }
    Tolerate("setting raw 8N1 at " + std::to_string(settings_.baud) + " baud (tcsetattr)", err);
  }
  fd_ = fd;
  return Status::Ok();
}

void TermiosLink::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status TermiosLink::Write(std::string_view bytes, const CallContext& ctx) {
  if (fd_ < 0) return NotOpen();
  return WriteAll(fd_, settings_.port, bytes, ctx);
}

Result<std::string> TermiosLink::Read(TimePoint until, const CallContext& ctx) {
  if (fd_ < 0) return NotOpen();
  return ReadAvailable(fd_, settings_.port, until, ctx);
}

Status TermiosLink::FlushInput() {
  if (fd_ < 0) return NotOpen();
  if (::tcflush(fd_, TCIFLUSH) != 0) {
    const int err = errno;
    if (!IsUnsupported(err)) return VanishedError(settings_.port, "flushing input", err);
    Tolerate("flushing the input buffer (tcflush)", err);
  }
  return Status::Ok();
}

Status TermiosLink::SetRts(bool on) {
  if (fd_ < 0) return NotOpen();
  int bits = TIOCM_RTS;
  if (::ioctl(fd_, on ? TIOCMBIS : TIOCMBIC, &bits) != 0) {
    const int err = errno;
    if (!IsUnsupported(err)) return VanishedError(settings_.port, "setting RTS", err);
    Tolerate(on ? "raising RTS" : "dropping RTS", err);
  }
  return Status::Ok();
}

}  // namespace brdf::drivers::serial
