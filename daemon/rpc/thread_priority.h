// Who goes first in brdfd when the cores are busy (issue 40): the nice values of its threads, in
// one place. Lower runs first; Linux weighs a thread's share of a busy core by its nice value (each
// step ~1.25×), so the control plane at 0 gets ~3× the share of Interpolate's loop at 5 and ~9×
// that of a stream's thread at 10.
//  - the control plane (control_loop.h): -5 where allowed (CAP_SYS_NICE or RLIMIT_NICE ≥ 25: the
//    systemd unit's LimitNICE=-5), else 0, as the session's executor and the rig's threads; and a
//    slice of 0.1 ms (kControlSlice). A share is not a wake-up: Linux's EEVDF scheduler (6.6 on)
//    lets the running thread finish its slice (~1.4 ms on two cores, up to a tick) before a woken
//    one runs, whatever their nice values, unless the woken one asked for a shorter slice (Linux
//    ≥ 6.12, sched_setattr's sched_runtime; no privilege needed, ignored by older kernels). A
//    control thread runnable 16 ms behind nice-10 threads was seen (perf sched, 2026-12-07);
//  - Interpolate's loop and slow lane (api/interpolate_loop.h): 5, analysts' calls that take
//    microseconds each but come by the thousand;
//  - the stream pump's threads (api/stream_pump.h): 10 for good, brdfd's own;
//  - a thread of gRPC's pool while it computes a stream's answer, holding a work permit
//    (stream_registry.h: exports, batches, RenderAppearance): 10, and back to 0 when it gives the
//    permit back, before it writes or waits. gRPC's threads poll the transport for every
//    connection (one epoll set per process): a pool thread blocked in a stream's write may be the
//    one that reads the operator's next call, so none is left at 10 while it waits. Back to 0
//    needs CAP_SYS_NICE or RLIMIT_NICE ≥ 20 (the unit's LimitNICE=-5 gives 25); without it a
//    pool thread that computed once stays at 10, as all did before 2026-12-07.
#pragma once

#include <chrono>

namespace brdf::daemon {

inline constexpr int kControlNice = -5;
inline constexpr int kInterpolateNice = 5;
inline constexpr int kStreamNice = 10;
// The control plane's slice: the shortest Linux takes (0.1 ms).
inline constexpr std::chrono::microseconds kControlSlice{100};

// setpriority on the calling thread (its tid); false when not allowed (the value stays).
bool SetThisThreadNice(int nice);

// SCHED_OTHER at `nice` with a slice of `slice` (sched_setattr's sched_runtime) on the calling
// thread; false when the nice value is not allowed (nothing changes then).
bool SetThisThreadNiceAndSlice(int nice, std::chrono::nanoseconds slice);

// The calling thread's name as ps, top and /proc/PID/task/TID/comm show it (at most 15
// characters): "ctl-plane" (the control plane), "interp-loop" and "interp-slow" (Interpolate).
void NameThisThread(const char* name);

}  // namespace brdf::daemon
