#include "drivers/serial/command_channel.h"

#include <algorithm>

#include "drivers/serial/context_wait.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers::serial {

CommandChannel::CommandChannel(ChannelOptions options, LinkFactory link_factory)
    : options_(std::move(options)), link_factory_(std::move(link_factory)) {
  framing_.quiet_gap = options_.quiet_gap;
  framing_.stall_timeout = options_.stall_timeout;
  framing_.max_reply_bytes = options_.max_reply_bytes;
  framing_.device = options_.serial.device;
}

CommandChannel::~CommandChannel() {
  Close();
}

Status CommandChannel::Open() {
  Close();
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<SerialLink> link,
                        link_factory_(options_.serial, options_.log));
  BRDF_RETURN_IF_ERROR(link->Open(port_seen_));
  port_seen_ = true;
  lost_ = false;
  link_ = std::move(link);
  return Status::Ok();
}

void CommandChannel::Close() {
  if (link_) link_->Close();
  link_.reset();
  late_reply_until_.reset();
}

Status CommandChannel::WriteCommand(std::string_view bytes, const CallContext& ctx) {
  if (options_.char_gap.count() <= 0) return link_->Write(bytes, ctx);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i > 0) BRDF_RETURN_IF_ERROR(WaitChecked(options_.char_gap, ctx, "typing a command"));
    BRDF_RETURN_IF_ERROR(link_->Write(bytes.substr(i, 1), ctx));
  }
  return Status::Ok();
}

Status CommandChannel::Settle(const CallContext& ctx) {
  if (!link_) {
    return FailedPrecondition(options_.serial.device + " on " + port() + " is not open");
  }
  BRDF_RETURN_IF_ERROR(DiscardLateReply(ctx));
  const auto now = ctx.clock().Now();
  if (now < next_command_at_) {
    BRDF_RETURN_IF_ERROR(WaitChecked(next_command_at_ - now, ctx, "pacing commands"));
  }
  return link_->FlushInput();
}

Status CommandChannel::Send(std::string_view bytes, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(Settle(ctx));
  Status written = WriteCommand(bytes, ctx);
  next_command_at_ = ctx.clock().Now() + options_.command_pacing;
  if (written.code() == StatusCode::kDisconnected) {
    Close();
    lost_ = true;
  }
  return written;
}

Result<std::string> CommandChannel::Exchange(std::string_view command, const ReplyShape& shape,
                                             const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(Settle(ctx));
  Status written = WriteCommand(std::string(command) + options_.line_end, ctx);
  const auto sent_at = ctx.clock().Now();
  if (!written.ok()) {
    next_command_at_ = sent_at + options_.command_pacing;
    if (written.code() == StatusCode::kDisconnected) {
      Close();
      lost_ = true;
    }
    return written.WithContext(options_.serial.device + " " + std::string(command));
  }
  return Read(command, shape, ctx, sent_at);
}

Result<std::string> CommandChannel::ReadMore(std::string_view command, const ReplyShape& shape,
                                             const CallContext& ctx) {
  if (!link_) {
    return FailedPrecondition(options_.serial.device + " on " + port() + " is not open");
  }
  return Read(command, shape, ctx, ctx.clock().Now());
}

Result<std::string> CommandChannel::Read(std::string_view command, const ReplyShape& shape,
                                         const CallContext& ctx,
                                         std::chrono::steady_clock::time_point sent_at) {
  const ReplyRequest request{command, shape.lines, shape.first_byte_timeout, shape.first_line,
                             shape.lines_after_first};
  Result<std::string> reply = ReadReply(*link_, request, framing_, ctx);
  next_command_at_ = ctx.clock().Now() + options_.command_pacing;
  if (reply.ok()) return reply;
  switch (reply.status().code()) {
    case StatusCode::kDisconnected:
      Close();
      lost_ = true;
      return reply.status().WithContext(options_.serial.device + " " + std::string(command));
    case StatusCode::kCancelled:
    case StatusCode::kTimeout: {
      // The meter may still answer what it received: remember until when.
      if (const auto until = LateReplyDeadline(sent_at, shape.first_byte_timeout, ctx.clock().Now(),
                                               reply.status().code() == StatusCode::kTimeout)) {
        late_reply_until_ = std::max(late_reply_until_.value_or(*until), *until);
      }
      if (reply.status().code() == StatusCode::kCancelled) {
        return reply.status().WithContext(options_.serial.device + " " + std::string(command));
      }
      return reply.status();
    }
    default:
      return reply.status();
  }
}

Status CommandChannel::DiscardLateReply(const CallContext& ctx) {
  if (!late_reply_until_) return Status::Ok();
  const auto until = *late_reply_until_;
  const auto now = ctx.clock().Now();
  late_reply_until_.reset();
  if (now >= until) return Status::Ok();
  Result<std::string> late =
      ReadReply(*link_, {"an abandoned command", 1, until - now}, framing_, ctx);
  if (late.ok()) {
    options_.log("discarded a late reply on " + port() + ": \"" + Printable(*late) + "\"");
    return Status::Ok();
  }
  const StatusCode code = late.status().code();
  if (code == StatusCode::kDisconnected) {
    Close();
    lost_ = true;
  }
  if (code == StatusCode::kCancelled || code == StatusCode::kDisconnected || ctx.expired()) {
    return late.status();
  }
  return Status::Ok();
}

}  // namespace brdf::drivers::serial
