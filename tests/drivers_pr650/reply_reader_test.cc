// Framing: the reply reader against a scripted byte source standing in for the meter's serial
// line (bytes arriving at set times, in pieces, with any line ends).
#include "drivers/serial/reply_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <deque>
#include <thread>

namespace brdf::drivers::serial {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using SteadyClock = std::chrono::steady_clock;

// Delivers scripted chunks, each at its time after construction. A blocking read does not see a
// chunk that lands within `blind` of the read's end (poll timing out just as the byte lands); a
// non-blocking read (end already past) returns whatever is due by now.
class ScriptedLink final : public SerialLink {
 public:
  struct Chunk {
    std::chrono::milliseconds at;
    std::string bytes;
    bool vanish = false;  // the port goes away at this time instead
  };
  explicit ScriptedLink(std::deque<Chunk> chunks, std::chrono::milliseconds blind = 0ms)
      : start_(SteadyClock::now()), chunks_(std::move(chunks)), blind_(blind) {}

  Status Open(bool) override { return Status::Ok(); }
  void Close() override {}
  bool is_open() const override { return true; }
  const std::string& port() const override { return port_; }
  Status Write(std::string_view, const CallContext&) override { return Status::Ok(); }
  Status FlushInput() override { return Status::Ok(); }
  Status SetRts(bool) override { return Status::Ok(); }

  Result<std::string> Read(TimePoint until, const CallContext& ctx) override {
    const auto end = std::min(until, ctx.deadline());
    const bool blocking = end > SteadyClock::now();
    while (true) {
      if (ctx.cancelled()) return Cancelled("scripted read cancelled");
      const auto now = SteadyClock::now();
      if (!chunks_.empty()) {
        const auto due = start_ + chunks_.front().at;
        if (due <= now && (!blocking || due < end - blind_)) {
          Chunk c = chunks_.front();
          chunks_.pop_front();
          if (c.vanish) return Disconnected("scripted port vanished");
          return c.bytes;
        }
      }
      if (now >= end) return std::string();
      std::this_thread::sleep_for(std::min<SteadyClock::duration>(end - now, 1ms));
    }
  }

 private:
  std::string port_ = "/dev/scripted";
  SteadyClock::time_point start_;
  std::deque<Chunk> chunks_;
  std::chrono::milliseconds blind_;
};

FramingOptions Framing(std::chrono::milliseconds quiet = 30ms,
                       std::chrono::milliseconds stall = 300ms) {
  FramingOptions f;
  f.quiet_gap = quiet;
  f.stall_timeout = stall;
  return f;
}

CallContext Ctx(std::chrono::milliseconds timeout = 5s, CancelToken cancel = CancelToken()) {
  return CallContext::WithTimeout(timeout, std::move(cancel));
}

TEST(ReadReply, OneLineInPieces) {
  ScriptedLink link({{0ms, "0"}, {5ms, "0"}, {10ms, "0\r"}, {15ms, "\n"}});
  auto r = ReadReply(link, {"B3", 1, 1s}, Framing(), Ctx());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(*r, "000\r\n");
}

TEST(ReadReply, WaitsForAllExpectedLinesAcrossGapsLongerThanTheQuietGap) {
  ScriptedLink link({{0ms, "00,0\r\n"}, {80ms, "1.0E+00\r\n"}, {160ms, "0380.,1.0E+00\r\n"}});
  auto r = ReadReply(link, {"D5", 3, 1s}, Framing(30ms, 300ms), Ctx());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(*r, "00,0\r\n1.0E+00\r\n0380.,1.0E+00\r\n");
}

TEST(ReadReply, FirstLineIsSeenOnceWhileTheRestIsStillOnTheWay) {
  // A blank line first (ignored), the status line in two pieces, then the data 150 ms later.
  ScriptedLink link(
      {{0ms, "\r\n1"}, {5ms, "8,0\r"}, {10ms, "\n1.0E+00\r\n"}, {150ms, "0380.,1.0E+00\r\n"}});
  const auto start = SteadyClock::now();
  std::vector<std::string> seen;
  SteadyClock::duration seen_after{};
  ReplyRequest request{"M5", 3, 1s};
  request.first_line = [&](std::string_view line) {
    seen.emplace_back(line);
    seen_after = SteadyClock::now() - start;
  };
  auto r = ReadReply(link, request, Framing(30ms, 300ms), Ctx());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(seen, std::vector<std::string>{"18,0"});
  EXPECT_LT(seen_after, 140ms);  // before the last line, which arrives at 150 ms
  EXPECT_GE(SteadyClock::now() - start, 150ms);
}

TEST(ReadReply, BytesWithinTheQuietGapBelongToTheReply) {
  ScriptedLink link({{0ms, "000\r\n"}, {10ms, "stray\r\n"}});
  auto r = ReadReply(link, {"M0", 1, 1s}, Framing(40ms), Ctx());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(*r, "000\r\nstray\r\n");
}

TEST(ReadReply, EveryLineEndVariantCompletesLines) {
  for (const char* reply : {"a\rb\rc\r", "a\nb\nc\n", "a\r\nb\r\nc\r\n", "a\rb\r\nc\n"}) {
    ScriptedLink link({{0ms, reply}});
    auto r = ReadReply(link, {"X", 3, 1s}, Framing(), Ctx());
    ASSERT_TRUE(r.ok()) << reply << ": " << r.status().ToString();
    EXPECT_EQ(*r, reply);
  }
}

TEST(ReadReply, SilenceIsATimeoutNamingTheCommand) {
  ScriptedLink link({});
  const auto start = SteadyClock::now();
  auto r = ReadReply(link, {"D110", 1, 100ms}, Framing(), Ctx());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kTimeout);
  EXPECT_THAT(r.status().message(), HasSubstr("did not answer D110 within 100 ms"));
  EXPECT_GE(SteadyClock::now() - start, 100ms);
}

TEST(ReadReply, AReplyArrivingAtTheLastMomentCounts) {
  // Lands 2 ms before the first-byte deadline, too late for the blocking wait to see it: the final
  // look at the deadline finds it (old drivers counted such a reply as "no response").
  ScriptedLink link({{98ms, "000\r\n"}}, 5ms);
  auto r = ReadReply(link, {"B3", 1, 100ms}, Framing(), Ctx());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(*r, "000\r\n");
}

TEST(ReadReply, AReplyStartedBeforeTheDeadlineMayFinishAfterIt) {
  ScriptedLink link({{90ms, "00"}, {130ms, "0\r\n"}});
  auto r = ReadReply(link, {"B3", 1, 100ms}, Framing(), Ctx());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(*r, "000\r\n");
}

TEST(ReadReply, TruncatedReplyIsAProtocolError) {
  ScriptedLink link({{0ms, "00,0\r\n1.0E"}});
  auto r = ReadReply(link, {"D5", 103, 1s}, Framing(20ms, 100ms), Ctx());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(r.status().message(), HasSubstr("truncated"));
  EXPECT_THAT(r.status().message(), HasSubstr("1 of 103 line(s)"));
}

TEST(ReadReply, RunawayReplyIsAProtocolError) {
  ScriptedLink link({{0ms, std::string(5000, 'x')}});
  FramingOptions f = Framing();
  f.max_reply_bytes = 4096;
  auto r = ReadReply(link, {"D5", 103, 1s}, f, Ctx());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kProtocolError);
  EXPECT_THAT(r.status().message(), HasSubstr("baud"));
}

TEST(ReadReply, VanishingPortIsDisconnected) {
  ScriptedLink link({{0ms, "00,0\r\n"}, {10ms, "", true}});
  auto r = ReadReply(link, {"D5", 103, 1s}, Framing(), Ctx());
  EXPECT_EQ(r.status().code(), StatusCode::kDisconnected);
}

TEST(ReadReply, CancellationEndsTheWaitPromptly) {
  ScriptedLink link({});
  CancelToken cancel;
  std::thread canceller([cancel]() mutable {
    std::this_thread::sleep_for(50ms);
    cancel.Cancel("operator pressed stop");
  });
  const auto start = SteadyClock::now();
  auto r = ReadReply(link, {"M0", 1, 30s}, Framing(), Ctx(60s, cancel));
  canceller.join();
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_LT(SteadyClock::now() - start, 5s);  // long before the 30 s reply timeout
}

TEST(ReadReply, CallDeadlineMidReplyIsATimeout) {
  ScriptedLink link({{0ms, "00,0\r\n"}, {50ms, "1.0E+00\r\n"}});
  auto r = ReadReply(link, {"D5", 103, 1s}, Framing(30ms, 2s), Ctx(150ms));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kTimeout);
  EXPECT_THAT(r.status().message(), HasSubstr("2 of 103 line(s)"));
}

}  // namespace
}  // namespace brdf::drivers::serial
