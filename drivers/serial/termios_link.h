// SerialLink over plain POSIX termios, for pseudo-terminals (the simulator, socat pairs), which
// libserialport cannot open. Settings a pty does not support (modem lines, some termios flags)
// fail with ENOTTY or EINVAL: those are logged and tolerated.
#pragma once

#include "drivers/serial/serial_link.h"

namespace brdf::drivers::serial {

class TermiosLink final : public SerialLink {
 public:
  TermiosLink(SerialSettings settings, LogSink log);
  ~TermiosLink() override;
  TermiosLink(const TermiosLink&) = delete;
  TermiosLink& operator=(const TermiosLink&) = delete;

  Status Open(bool seen_before) override;
  void Close() override;
  bool is_open() const override { return fd_ >= 0; }
  const std::string& port() const override { return settings_.port; }
  Status Write(std::string_view bytes, const CallContext& ctx) override;
  Result<std::string> Read(TimePoint until, const CallContext& ctx) override;
  Status FlushInput() override;
  Status SetRts(bool on) override;

 private:
  Status NotOpen() const;
  void Tolerate(std::string_view what, int err);

  SerialSettings settings_;
  LogSink log_;
  int fd_ = -1;
};

}  // namespace brdf::drivers::serial
