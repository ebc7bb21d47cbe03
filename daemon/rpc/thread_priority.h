// Who goes first in brdfd when the cores are busy (issue 40): the nice values of its threads, in
// one place. Lower runs first; Linux weighs a thread's share of a busy core by its nice value (each
// step ~1.25×), so the control plane at 0 gets ~3× the share of Interpolate's loop at 5 and ~9×
// that of a stream's thread at 10.
//  - the control plane (control_loop.h): -5 where allowed (CAP_SYS_NICE or RLIMIT_NICE ≥ 25: the
//    systemd unit's LimitNICE=-5), else 0, as the session's executor and the rig's threads;
//  - Interpolate's loop and slow lane (api/interpolate_loop.h): 5, analysts' calls that take
//    microseconds each but come by the thousand;
//  - a stream's thread while it is open (stream_registry.h): 10, analysts' streams and the heavy
//    calls (exports, batches, RenderAppearance). A thread cannot come back below its nice value
//    without the privilege above; gRPC's pool threads that served a stream then stay at 10.
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
