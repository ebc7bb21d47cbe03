// Framing: reading one whole reply off the serial link.
//
// A reply is complete when it holds the expected number of lines, ends with a line end and then
// the link has been quiet for the quiet gap (~50 ms): the meter's replies may arrive in pieces,
// and anything still trickling in belongs to this reply, not the next. Lines may end in CR LF, LF
// or a bare CR. Bytes arriving in the last moment of the wait count: the link is read once more
// at the deadline before "no reply" is declared.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

#include "core/call_context.h"
#include "core/status.h"
#include "drivers/serial/serial_link.h"

namespace brdf::drivers::serial {

struct FramingOptions {
  // Silence after the last byte that ends a complete reply.
  std::chrono::steady_clock::duration quiet_gap = std::chrono::milliseconds(50);
  // Silence after the last byte that ends an incomplete reply: the reply is truncated.
  std::chrono::steady_clock::duration stall_timeout = std::chrono::seconds(1);
  // Longer replies are garbage (a D5 report is about 1.7 kB; a PR-670's about 3.5 kB, a
  // CS-2000's spectral block about 1.1 kB).
  std::size_t max_reply_bytes = 16 * 1024;
  // The meter on the line, for messages ("PR-650 reply to D5 on /dev/ttyUSB0 stopped ...").
  std::string device = "PR-650";
};

struct ReplyRequest {
  std::string_view command;  // the command answered, for messages
  std::size_t lines = 1;     // complete lines that make the whole reply
  std::chrono::steady_clock::duration first_byte_timeout = std::chrono::seconds(2);
  // Called once, as soon as the reply's first line is complete (without its line end), while the
  // rest may still be on the wire: a report's status line can be acted on before its data has
  // arrived (M5: the stage may leave once the measurement is known good).
  std::function<void(std::string_view first_line)> first_line = nullptr;
  // Called once with the reply's first line (after first_line): the number of lines the whole
  // reply has, when the first line tells (a PR-670 answers M5 with its error code alone instead
  // of the 202-line report). 0 keeps `lines`.
  std::function<std::size_t(std::string_view first_line)> lines_after_first = nullptr;
};

// Reads one reply. Errors:
//  kTimeout        nothing arrived within first_byte_timeout ("did not answer"), or the context's
//                  deadline passed mid-reply;
//  kProtocolError  the reply stopped before it was complete (stall_timeout) or grew too long;
//  kCancelled, kDisconnected from the link.
Result<std::string> ReadReply(SerialLink& link, const ReplyRequest& request,
                              const FramingOptions& framing, const CallContext& ctx);

}  // namespace brdf::drivers::serial
