#include "drivers/line_meter/connection.h"

#include <iostream>
#include <utility>

namespace brdf::drivers {

namespace {

serial::ChannelOptions ChannelFor(const LineMeterOptions& o, std::string line_end,
                                  std::chrono::milliseconds char_gap) {
  serial::ChannelOptions c;
  c.serial = {o.port, o.baud, o.hardware_flow_control, o.model};
  c.line_end = std::move(line_end);
  c.char_gap = char_gap;
  c.command_pacing = o.command_pacing;
  c.quiet_gap = o.quiet_gap;
  c.stall_timeout = o.stall_timeout;
  c.log = o.log;
  return c;
}

}  // namespace

serial::LogSink StderrLogUnlessSet(serial::LogSink log, std::string_view prefix) {
  if (log) return log;
  return [prefix = std::string(prefix)](std::string_view m) {
    std::clog << prefix << ": " << m << '\n';
  };
}

LineMeterConnection::LineMeterConnection(const LineMeterOptions& options, std::string line_end,
                                         std::chrono::milliseconds char_gap,
                                         serial::CommandChannel::LinkFactory link_factory)
    : port_(options.port),
      log_(options.log),
      channel_(ChannelFor(options, std::move(line_end), char_gap), std::move(link_factory)),
      model_(options.model) {}

Status LineMeterConnection::Connect(const std::function<Status()>& enter_remote_mode) {
  channel_.Close();
  Status status = channel_.Open();
  if (status.ok()) status = enter_remote_mode();
  if (!status.ok()) {
    channel_.Close();
    return status;
  }
  connected_ = true;
  lost_connection_ = false;
  return Status::Ok();
}

void LineMeterConnection::Disconnect(const std::function<void()>& leave_remote_mode) {
  if (channel_.is_open() && connected_) leave_remote_mode();
  channel_.Close();
  connected_ = false;
  lost_connection_ = false;
}

Status LineMeterConnection::RequireConnected() const {
  if (connected_) return Status::Ok();
  if (lost_connection_) {
    return Disconnected(Where() +
                        " lost its connection earlier: connect again once the port is "
                        "back");
  }
  return FailedPrecondition(Where() + " is not connected: call Connect first");
}

bool LineMeterConnection::NoteIfLost() {
  if (!channel_.lost()) return false;
  connected_ = false;
  lost_connection_ = true;
  return true;
}

std::string LineMeterConnection::Where() const {
  return model_ + " on " + port_;
}

}  // namespace brdf::drivers
