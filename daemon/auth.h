// Who is calling: bearer tokens from the configuration ([[auth.tokens]]) mapped to a role
// (operator, analyst) and the token's name. A call carries the metadata
// "authorization: Bearer <token>". Mutating Control calls need an operator; read-only calls
// (ValidatePlan, GetSession, ListSessions, ListSessionEvents, GetRigStatus, WatchSession, Data.*,
// Interpolation.*) accept either role (brdf.proto's header). The health service and reflection
// need no token.
//
// Tokens are secrets: they are never logged and never stored (the audit log gets the token's
// NAME). A presented token is compared with EVERY configured token in time that depends only on
// the lengths, never on where the first differing byte is, so response timing does not let a
// client guess a token byte by byte.
//
// Refusals are logged without the token: PERMISSION_DENIED as a warning with the token's name,
// the RPC and the peer; UNAUTHENTICATED at debug level (the peer and why), so that a scan cannot
// flood the log.
//
// With no tokens configured the API is open: every caller is an operator named "anonymous" (the
// configuration's documented mode for a daemon bound to localhost; main warns otherwise).
#pragma once

#include <grpcpp/server_context.h>
#include <grpcpp/support/status.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/config.h"
#include "daemon/session_manager.h"

namespace brdf::daemon {

// What a call needs.
enum class Access {
  kRead,     // analyst or operator
  kControl,  // operator only
};

// Why a call was refused.
enum class AuthFailure {
  kNone,
  kMissing,    // no "authorization" metadata
  kMalformed,  // not "Bearer <token>"
  kUnknown,    // no configured token matches
};

// The caller behind an accepted token.
struct Caller {
  Role role = Role::kAnalyst;
  std::string name;  // the token's configured name ("lab-pc"), never the token
  // As the session manager's audit wants it.
  Actor ToActor() const { return Actor{RoleName(role), name}; }
};

// What the method at `path` (":path", "/brdf.v1.Control/PauseSession") needs: nullopt for the
// calls open to everyone (grpc.health.v1.Health, grpc.reflection.*), kControl for Control's
// mutating verbs, kRead for every other method, known or not.
std::optional<Access> MethodAccess(std::string_view path);

// The method's name for messages: what follows the last '/' of `path`, at most 64 printable
// characters ("PauseSession").
std::string MethodName(std::string_view path);

// True when a and b hold the same bytes. Runs over max(|a|, |b|) bytes without an early exit.
bool ConstantTimeEquals(std::string_view a, std::string_view b);

class Authenticator {
 public:
  // Longest "authorization" value examined; longer ones are refused unread.
  static constexpr std::size_t kMaxHeaderBytes = 4096;

  explicit Authenticator(std::vector<TokenConfig> tokens);

  // False when no tokens are configured: every call is allowed (as an operator).
  bool enabled() const { return !tokens_.empty(); }
  std::size_t token_count() const { return tokens_.size(); }

  // The caller for an "authorization" metadata value ("Bearer <token>"; the scheme is
  // case-insensitive, as in RFC 7235). `header` empty: no metadata. Sets *failure on refusal.
  bool Identify(std::string_view header, Caller* caller, AuthFailure* failure) const;

  // The whole check of one RPC: reads the metadata of `context`, identifies the caller and checks
  // the role against `access`. OK with *caller set, else UNAUTHENTICATED (no or unknown token) or
  // PERMISSION_DENIED (an analyst on a control call). `rpc` names the call in the message.
  grpc::Status Authorize(const grpc::ServerContextBase& context, Access access,
                         std::string_view rpc, Caller* caller) const;
  // The same check on an "authorization" value (`header`, empty: none) for a call from `peer`
  // (for the log; may be empty). Authorize and the token gate (token_gate.h) both use it.
  grpc::Status Check(std::string_view header, Access access, std::string_view rpc,
                     std::string_view peer, Caller* caller) const;

 private:
  std::vector<TokenConfig> tokens_;
};

}  // namespace brdf::daemon
