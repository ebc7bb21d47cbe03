// Who runs at which nice value while a stream is open (daemon/rpc/thread_priority.h, issue 40):
// a computing stream's thread is at 10 only while it holds a work permit, and back at 0 when it
// gives the permit back to write or wait (where this user may lower a nice value), since a thread
// of gRPC's pool polls the transport for every connection, the operator's too. A stream that
// does not compute leaves its thread's nice value alone.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <memory>
#include <thread>

#include "daemon/rpc/stream_registry.h"
#include "daemon/rpc/thread_priority.h"

namespace brdf::daemon {
namespace {

int ThisThreadNice() {
  return ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
}

// This user may lower a thread's nice value from 10 back to 0 (CAP_SYS_NICE, or RLIMIT_NICE ≥ 20
// as the systemd unit's LimitNICE=-5 gives).
bool MayLowerNice() {
  rlimit limit{};
  return ::geteuid() == 0 || (::getrlimit(RLIMIT_NICE, &limit) == 0 && limit.rlim_cur >= 20);
}

TEST(StreamPriorityTest, AComputingStreamIsAtNice10OnlyWhileItHoldsAWorkPermit) {
  if (!MayLowerNice()) GTEST_SKIP() << "this user may not lower a nice value (RLIMIT_NICE < 20)";
  if (ThisThreadNice() != 0) GTEST_SKIP() << "the test runs reniced";
  StreamRegistry streams(ServerConfig{}, false);
  grpc::ServerContext context;
  int opened = -1, writing = -1, written = -1, ended = -1;
  std::thread call([&] {  // a thread of its own, as gRPC's pool gives each call
    std::unique_ptr<StreamRegistry::Slot> slot;
    ASSERT_TRUE(streams.Open(context, nullptr, "Export", &slot, /*computes=*/true).ok());
    opened = ThisThreadNice();
    slot->BeginWrite();  // gives the permit back: the write may wait for the client
    writing = ThisThreadNice();
    slot->EndWrite();  // the next permit: computes again
    written = ThisThreadNice();
    slot.reset();
    ended = ThisThreadNice();
  });
  call.join();
  EXPECT_EQ(opened, kStreamNice) << "computing, with its permit";
  EXPECT_EQ(writing, 0) << "writing: its thread may poll the operator's calls";
  EXPECT_EQ(written, kStreamNice) << "computing again";
  EXPECT_EQ(ended, 0) << "the stream ended";
}

TEST(StreamPriorityTest, AStreamThatDoesNotComputeLeavesItsThreadAlone) {
  if (ThisThreadNice() != 0) GTEST_SKIP() << "the test runs reniced";
  StreamRegistry streams(ServerConfig{}, false);
  grpc::ServerContext context;
  int opened = -1, ended = -1;
  std::thread call([&] {
    std::unique_ptr<StreamRegistry::Slot> slot;
    ASSERT_TRUE(streams.Open(context, nullptr, "health Watch", &slot).ok());
    opened = ThisThreadNice();
    slot.reset();
    ended = ThisThreadNice();
  });
  call.join();
  EXPECT_EQ(opened, 0);
  EXPECT_EQ(ended, 0);
}

}  // namespace
}  // namespace brdf::daemon
