#include "daemon/rpc/thread_priority.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdint>

namespace brdf::daemon {
namespace {

// The kernel's struct sched_attr, first version (linux/sched/types.h, which clashes with glibc's
// <sched.h>; glibc 2.36 has no sched_setattr).
struct SchedAttr {
  std::uint32_t size;
  std::uint32_t sched_policy;
  std::uint64_t sched_flags;
  std::int32_t sched_nice;
  std::uint32_t sched_priority;
  std::uint64_t sched_runtime;  // SCHED_OTHER: the slice asked for (Linux ≥ 6.12; ignored before)
  std::uint64_t sched_deadline;
  std::uint64_t sched_period;
};
static_assert(sizeof(SchedAttr) == 48);

}  // namespace

bool SetThisThreadNice(int nice) {
  return ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), nice) == 0;
}

bool SetThisThreadNiceAndSlice(int nice, std::chrono::nanoseconds slice) {
  SchedAttr attr{};
  attr.size = sizeof attr;
  attr.sched_policy = SCHED_OTHER;
  attr.sched_nice = nice;
  attr.sched_runtime = static_cast<std::uint64_t>(slice.count());
  return ::syscall(SYS_sched_setattr, 0, &attr, 0U) == 0;
}

void NameThisThread(const char* name) {
  (void)::pthread_setname_np(::pthread_self(), name);
}

}  // namespace brdf::daemon
