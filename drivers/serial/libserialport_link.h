// SerialLink over libserialport, for real serial ports (/dev/ttyUSB*, /dev/ttyS*). libserialport
// opens and configures the port, drives RTS and flushes; reads and writes wait on its file handle
// (sp_get_port_handle) so that a hang-up is told apart from "no data yet".
#pragma once

#include "drivers/serial/serial_link.h"

struct sp_port;

namespace brdf::drivers::serial {

class LibSerialPortLink final : public SerialLink {
 public:
  LibSerialPortLink(SerialSettings settings, LogSink log);
  ~LibSerialPortLink() override;
  LibSerialPortLink(const LibSerialPortLink&) = delete;
  LibSerialPortLink& operator=(const LibSerialPortLink&) = delete;

  Status Open(bool seen_before) override;
  void Close() override;
  bool is_open() const override { return port_ != nullptr; }
  const std::string& port() const override { return settings_.port; }
  Status Write(std::string_view bytes, const CallContext& ctx) override;
  Result<std::string> Read(TimePoint until, const CallContext& ctx) override;
  Status FlushInput() override;
  Status SetRts(bool on) override;

 private:
  Status NotOpen() const;

  SerialSettings settings_;
  LogSink log_;
  sp_port* port_ = nullptr;
  int fd_ = -1;
};

}  // namespace brdf::drivers::serial
