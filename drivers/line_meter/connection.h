// The connection of a meter driven in lines over a serial::CommandChannel (the PR-655/PR-670,
// the CS-2000/CS-3000): the channel, whether the meter is in remote mode, whether its port
// vanished, and the name messages give it ("PR-670 on /dev/ttyACM0"). The meter's driver says
// how it enters and leaves remote mode; this keeps the rest the same for every such meter.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <string_view>

#include "core/status.h"
#include "drivers/line_meter/options.h"
#include "drivers/serial/command_channel.h"

namespace brdf::drivers {

class LineMeterConnection {
 public:
  // Commands end with `line_end` and are typed `char_gap` apart per character (0: at once).
  LineMeterConnection(const LineMeterOptions& options, std::string line_end,
                      std::chrono::milliseconds char_gap,
                      serial::CommandChannel::LinkFactory link_factory);

  // Opens the port and runs `enter_remote_mode`; the port is closed again if either fails.
  Status Connect(const std::function<Status()>& enter_remote_mode);
  // Runs `leave_remote_mode` (best effort) if connected, then closes the port.
  void Disconnect(const std::function<void()>& leave_remote_mode);
  bool connected() const { return connected_; }

  // kFailedPrecondition before Connect, kDisconnected after the port vanished.
  Status RequireConnected() const;
  // After a failed exchange: true (and no longer connected) if the port vanished.
  bool NoteIfLost();

  serial::CommandChannel& channel() { return channel_; }
  // "PR-670 on /dev/ttyACM0": the model as last identified, and the port.
  std::string Where() const;
  void set_model(std::string model) { model_ = std::move(model); }
  void Log(const std::string& message) const { log_(message); }

 private:
  std::string port_;
  serial::LogSink log_;
  serial::CommandChannel channel_;
  bool connected_ = false;
  bool lost_connection_ = false;
  std::string model_;
};

// `log`, or a sink writing "<prefix>: message" lines to stderr when `log` is empty.
serial::LogSink StderrLogUnlessSet(serial::LogSink log, std::string_view prefix);

// `options` with a log to stderr ("<prefix>: message") when it has none.
template <typename Options>
Options WithStderrLog(Options options, std::string_view prefix) {
  options.log = StderrLogUnlessSet(std::move(options.log), prefix);
  return options;
}

}  // namespace brdf::drivers
