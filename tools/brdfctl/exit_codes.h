// brdfctl's exit status, one meaning each, so that scripts (deploy/quickstart.sh) can branch:
//   0  done
//   1  failure: the daemon is unreachable, a call failed for another reason, a local error
//   2  invalid argument: a bad plan (every problem is printed), a bad flag or value, a request the
//      daemon refused with INVALID_ARGUMENT
//   3  authentication: no token, a wrong token (UNAUTHENTICATED), or a token whose role may not
//      make the call (PERMISSION_DENIED)
//   4  the call worked but gave no result: `watch` saw the session end aborted or failed,
//      `interpolate` got no spectrum for the direction (an empty octant, outside the hull)
#pragma once

namespace brdf::ctl {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitInvalid = 2;
inline constexpr int kExitAuth = 3;
inline constexpr int kExitNoResult = 4;

}  // namespace brdf::ctl
