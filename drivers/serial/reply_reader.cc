#include "drivers/serial/reply_reader.h"

#include "drivers/serial/reply_lines.h"

namespace brdf::drivers::serial {

namespace {

long long Millis(std::chrono::steady_clock::duration d) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
}

bool Complete(std::string_view bytes, std::size_t lines) {
  return EndsWithLineEnd(bytes) && CountCompleteLines(bytes) >= lines;
}

std::string Progress(std::string_view bytes, std::size_t lines) {
  return std::to_string(CountCompleteLines(bytes)) + " of " + std::to_string(lines) + " line(s), " +
         std::to_string(bytes.size()) + " bytes, ending \"" +
         Printable(bytes.substr(bytes.size() > 24 ? bytes.size() - 24 : 0)) + "\"";
}

}  // namespace

Result<std::string> ReadReply(SerialLink& link, const ReplyRequest& request,
                              const FramingOptions& framing, const CallContext& ctx) {
  const Clock& clock = ctx.clock();
  const std::string command(request.command);
  const auto first_deadline = clock.Now() + request.first_byte_timeout;
  std::string reply;
  auto last_byte = clock.Now();
  bool first_line_seen = !request.first_line && !request.lines_after_first;
  std::size_t lines = request.lines;

  auto append = [&](const std::string& bytes) -> Status {
    reply += bytes;
    last_byte = clock.Now();
    if (!first_line_seen && CountCompleteLines(reply) > 0) {
      first_line_seen = true;
      const std::size_t begin = reply.find_first_not_of("\r\n");
      const std::string_view line =
          std::string_view(reply).substr(begin, reply.find_first_of("\r\n", begin) - begin);
      if (request.first_line) request.first_line(line);
      if (request.lines_after_first) {
        if (const std::size_t n = request.lines_after_first(line); n > 0) lines = n;
      }
    }
    if (reply.size() > framing.max_reply_bytes) {
      return ProtocolError(framing.device + " reply to " + command + " on " + link.port() +
                           " exceeds " + std::to_string(framing.max_reply_bytes) +
                           " bytes without ending: line noise or a wrong baud rate; check the "
                           "cable and that the meter is set to the configured baud rate");
    }
    return Status::Ok();
  };

  while (true) {
    auto until = first_deadline;
    if (!reply.empty()) {
      const bool complete = Complete(reply, lines);
      const auto gap = complete ? framing.quiet_gap : framing.stall_timeout;
      if (clock.Now() - last_byte >= gap) {
        if (complete) return reply;
        return ProtocolError(framing.device + " reply to " + command + " on " + link.port() +
                             " stopped after " + Progress(reply, lines) +
                             " and nothing more came for " +
                             std::to_string(Millis(framing.stall_timeout)) +
                             " ms: the reply is truncated; check the cable and retry");
      }
      until = last_byte + gap;
    }

    BRDF_ASSIGN_OR_RETURN(std::string bytes, link.Read(until, ctx));
    if (!bytes.empty()) {
      BRDF_RETURN_IF_ERROR(append(bytes));
      continue;
    }

    const bool deadline_passed = ctx.expired();
    const bool no_answer = reply.empty() && clock.Now() >= first_deadline;
    if (!deadline_passed && !no_answer) continue;

    // One last look before giving up: a reply that arrived in the final moment is a reply.
    BRDF_ASSIGN_OR_RETURN(std::string late, link.Read(clock.Now(), ctx));
    if (!late.empty()) BRDF_RETURN_IF_ERROR(append(late));
    if (deadline_passed) {
      if (Complete(reply, lines)) return reply;
      if (reply.empty()) {
        return Timeout(framing.device + " on " + link.port() + " did not answer " + command +
                       " before the call's deadline");
      }
      return Timeout("call deadline passed while reading the " + framing.device + "'s reply to " +
                     command + " on " + link.port() + " (" + Progress(reply, lines) + ")");
    }
    if (reply.empty()) {
      return Timeout(framing.device + " on " + link.port() + " did not answer " + command +
                     " within " + std::to_string(Millis(request.first_byte_timeout)) + " ms");
    }
  }
}

}  // namespace brdf::drivers::serial
