#include "daemon/rpc/thread_priority.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace brdf::daemon {

bool SetThisThreadNice(int nice) {
  return ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), nice) == 0;
}

}  // namespace brdf::daemon
