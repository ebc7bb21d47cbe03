// Fuzz target: the PR-650 reply framing (drivers/serial/reply_reader.h: ReadReply) driven from
// bytes. A scripted serial link delivers the input's chunks at the input's times on a virtual
// clock, so the fuzzer controls both what the meter sends and when (pieces, pauses longer than
// the quiet gap or the stall timeout, a vanishing port, a cancel), and a run takes microseconds.
//
// Input: [lines] [deadline] [max bytes], then chunks of [control] [length] [bytes...]; control's
// low 6 bits are the pause before the chunk in 10 ms units, bit 6 makes the port vanish there
// instead, bit 7 cancels the call there instead.
//
// Promises checked: an accepted reply is exactly the bytes delivered, ends with a line end, holds
// the requested lines and fits max_reply_bytes; a failure is one of the documented codes; the
// reader never spins without letting time pass.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/clock.h"
#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_lines.h"
#include "drivers/serial/reply_reader.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {
namespace {

using namespace std::chrono_literals;
using namespace brdf::drivers::pr650;
using namespace brdf::drivers::serial;

// Time moves only when the link says so (a read that waits, a chunk that arrives later).
class VirtualClock final : public Clock {
 public:
  TimePoint Now() const override { return now_; }
  bool SleepFor(Duration d, const CancelToken* cancel) const override {
    now_ += d;
    return cancel == nullptr || !cancel->cancelled();
  }
  void AdvanceTo(TimePoint t) const {
    if (t > now_) now_ = t;
  }

 private:
  mutable TimePoint now_ = TimePoint{} + 1h;
};

struct Chunk {
  Clock::TimePoint due;
  std::string bytes;
  bool vanish = false;
  bool cancel = false;
};

// The meter's side of the line, scripted by the input.
class ScriptedLink final : public SerialLink {
 public:
  ScriptedLink(const VirtualClock& clock, std::vector<Chunk> chunks, CancelToken cancel)
      : clock_(clock), chunks_(std::move(chunks)), cancel_(std::move(cancel)) {}

  Status Open(bool) override { return Status::Ok(); }
  void Close() override {}
  bool is_open() const override { return true; }
  const std::string& port() const override { return port_; }
  Status Write(std::string_view, const CallContext&) override { return Status::Ok(); }
  Status FlushInput() override { return Status::Ok(); }
  Status SetRts(bool) override { return Status::Ok(); }

  Result<std::string> Read(TimePoint until, const CallContext& ctx) override {
    ++reads_;
    BRDF_FUZZ_CHECK(reads_ < 100000, "ReadReply keeps reading without time passing");
    if (ctx.cancelled()) return Cancelled("scripted read cancelled");
    const TimePoint end = std::min(until, ctx.deadline());
    if (next_ < chunks_.size() && chunks_[next_].due <= std::max(end, clock_.Now())) {
      const Chunk& c = chunks_[next_++];
      clock_.AdvanceTo(c.due);
      if (c.cancel) {
        cancel_.Cancel("fuzz cancel");
        return Cancelled("scripted read cancelled");
      }
      if (c.vanish) return Disconnected("scripted port vanished");
      delivered_ += c.bytes;
      return c.bytes;
    }
    clock_.AdvanceTo(end);
    return std::string();
  }

  const std::string& delivered() const { return delivered_; }

 private:
  const VirtualClock& clock_;
  std::vector<Chunk> chunks_;
  CancelToken cancel_;
  std::size_t next_ = 0;
  std::string delivered_;
  std::string port_ = "/dev/fuzz";
  long reads_ = 0;
};

}  // namespace

int FuzzPr650Framing(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  const std::uint8_t lines_byte = in.Byte();
  const std::size_t lines =
      (lines_byte & 0x80) != 0 ? SpectrumReplyLines(WavelengthGrid{380, 4, 5}) : 1 + lines_byte % 4;
  const auto deadline = std::chrono::milliseconds(100 * (1 + in.Byte() % 64));
  FramingOptions framing;  // the driver's defaults: 50 ms quiet gap, 1 s stall timeout
  framing.max_reply_bytes = std::size_t{16} << (in.Byte() % 11);

  VirtualClock clock;
  CancelToken cancel;
  std::vector<Chunk> chunks;
  Clock::TimePoint t = clock.Now();
  while (!in.empty()) {
    const std::uint8_t control = in.Byte();
    const std::size_t length = in.Byte();
    t += std::chrono::milliseconds(10 * (control & 0x3f));
    chunks.push_back(
        {t, std::string(in.Take(length)), (control & 0x40) != 0, (control & 0x80) != 0});
  }

  ScriptedLink link(clock, std::move(chunks), cancel);
  const CallContext ctx(clock.Now() + deadline, cancel, clock);
  ReplyRequest request{"M5", lines, 2s};
  int first_lines = 0;
  std::string first_line;
  request.first_line = [&](std::string_view line) {
    ++first_lines;
    first_line = line;
    BRDF_FUZZ_CHECK(!line.empty(), "the first line handed over is empty");
    BRDF_FUZZ_CHECK(line.find_first_of("\r\n") == std::string_view::npos,
                    "the first line handed over holds a line end");
    (void)ParseSpectrumHeader(line, "M5");  // what the driver does with it
  };
  const Result<std::string> r = ReadReply(link, request, framing, ctx);
  BRDF_FUZZ_CHECK(first_lines <= 1, "the first line was handed over more than once");

  if (r.ok()) {
    BRDF_FUZZ_CHECK(first_lines == 1, "a complete reply's first line was never handed over");
    BRDF_FUZZ_CHECK(r->find(first_line) != std::string::npos,
                    "the first line handed over is not in the reply");
    BRDF_FUZZ_CHECK(*r == link.delivered(), "the reply is not exactly the bytes delivered");
    BRDF_FUZZ_CHECK(EndsWithLineEnd(*r), "accepted a reply without a final line end");
    BRDF_FUZZ_CHECK(CountCompleteLines(*r) >= lines, "accepted a reply with too few lines");
    BRDF_FUZZ_CHECK(r->size() <= framing.max_reply_bytes, "accepted an oversize reply");
    // What the driver does next with such a reply.
    if (lines == 1) (void)ParseStatusReply(*r, "M0");
    if (lines > 4) (void)ParseSpectrumReply(*r, WavelengthGrid{380, 4, 5});
  } else {
    const StatusCode code = r.status().code();
    BRDF_FUZZ_CHECK(code == StatusCode::kTimeout || code == StatusCode::kProtocolError ||
                        code == StatusCode::kCancelled || code == StatusCode::kDisconnected,
                    "undocumented error: " + r.status().ToString());
    BRDF_FUZZ_CHECK(!r.status().message().empty(), "an error without a message");
  }
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzPr650Framing)
