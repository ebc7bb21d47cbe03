// One command/reply conversation with a meter on a serial line, for the meters that came after
// the PR-650 (drivers/pr670, drivers/cs2000): open the port (exclusively, serial_link.h), wait out
// the pacing, empty the input buffer, write the command and its line end (a character at a time
// when the meter needs it), read the reply (reply_reader.h). A command abandoned while the meter
// may still answer (a timeout, a cancel) has its late reply discarded before the next command, so
// it is never read as the answer to that one. A port that vanishes closes the link and says so
// (kDisconnected); the caller connects again once the port is back.
//
// It lives beside the PR-650's link layer, which it uses; the PR-650 driver keeps its own exchange
// (RTS wake-up, M5 pipelining), which predates this class.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "core/call_context.h"
#include "core/status.h"
#include "drivers/serial/reply_reader.h"
#include "drivers/serial/serial_link.h"

namespace brdf::drivers::serial {

struct ChannelOptions {
  using Millis = std::chrono::milliseconds;

  SerialSettings serial;        // port, baud, flow control and the meter's name for messages
  std::string line_end = "\r";  // appended to every command ("\r" PR-670, "\n" CS-2000)
  Millis char_gap{0};           // > 0: written a character at a time, this far apart
  Millis command_pacing{100};   // pause after an exchange before the next command
  Millis quiet_gap{50};         // silence that ends a complete reply
  Millis stall_timeout{1000};   // silence that ends an incomplete reply (truncated)
  std::size_t max_reply_bytes = 16 * 1024;
  LogSink log;  // diagnostics; required
};

// What one reply looks like: its line count (or the count its first line tells), how long the
// meter may take to start it, and who wants its first line early.
struct ReplyShape {
  std::size_t lines = 1;
  std::chrono::steady_clock::duration first_byte_timeout = std::chrono::seconds(2);
  std::function<void(std::string_view)> first_line = nullptr;
  std::function<std::size_t(std::string_view)> lines_after_first = nullptr;
};

class CommandChannel {
 public:
  using LinkFactory =
      std::function<Result<std::unique_ptr<SerialLink>>(const SerialSettings&, LogSink)>;

  explicit CommandChannel(ChannelOptions options, LinkFactory link_factory = MakeSerialLink);
  ~CommandChannel();
  CommandChannel(const CommandChannel&) = delete;
  CommandChannel& operator=(const CommandChannel&) = delete;

  // Opens the port (a port missing after it once opened has vanished: kDisconnected).
  Status Open();
  void Close();
  bool is_open() const { return link_ != nullptr; }
  // The link went down under an exchange (vs closed by the caller).
  bool lost() const { return lost_; }
  const std::string& port() const { return options_.serial.port; }
  const std::string& device() const { return options_.serial.device; }

  // Writes `bytes` as they are (no line end added), a character at a time when char_gap is set.
  Status Send(std::string_view bytes, const CallContext& ctx);
  // Sends `command` + the line end and reads the reply.
  Result<std::string> Exchange(std::string_view command, const ReplyShape& shape,
                               const CallContext& ctx);
  // Reads a further reply to `command` without sending anything (the CS-2000's MEAS answers
  // twice: the measuring time at once, the completion later).
  Result<std::string> ReadMore(std::string_view command, const ReplyShape& shape,
                               const CallContext& ctx);
  // Waits out the pacing, then discards whatever is waiting in the input buffer.
  Status Settle(const CallContext& ctx);

 private:
  Status DiscardLateReply(const CallContext& ctx);
  Status WriteCommand(std::string_view bytes, const CallContext& ctx);
  Result<std::string> Read(std::string_view command, const ReplyShape& shape,
                           const CallContext& ctx, std::chrono::steady_clock::time_point sent_at);

  ChannelOptions options_;
  LinkFactory link_factory_;
  FramingOptions framing_;
  std::unique_ptr<SerialLink> link_;
  bool port_seen_ = false;
  bool lost_ = false;
  std::chrono::steady_clock::time_point next_command_at_{};
  std::optional<std::chrono::steady_clock::time_point> late_reply_until_;
};

}  // namespace brdf::drivers::serial
