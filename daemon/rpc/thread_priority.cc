#include "daemon/rpc/thread_priority.h"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace brdf::daemon {

bool SetThisThreadNice(int nice) {
  return ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), nice) == 0;
}

void NameThisThread(const char* name) {
  (void)::pthread_setname_np(::pthread_self(), name);
}

}  // namespace brdf::daemon
