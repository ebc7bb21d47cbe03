// Who is calling: bearer tokens from the configuration ([[auth.tokens]]) mapped to a role
// (operator, analyst) and the token's name. A call carries the metadata
// "authorization: Bearer <token>". Mutating Control calls need an operator; read-only calls
// (ValidatePlan, GetSession, ListSessions, ListSessionEvents, ListAdaptiveRounds, GetRigStatus,
// WatchSession, Data.*, Interpolation.*) accept either role (brdf.proto's header). The health
// service and reflection need no token.
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

#include "daemon/config/config.h"
#include "daemon/sessions/session_id.h"

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

  // The one check of a call, made at its door and only there: the token gate for calls from the
  // network (token_gate.h), the web gateway for the browser's calls inside the process
  // (gateway/json_rpc.h). The access the method at `path` needs comes from MethodAccess; the
  // "authorization" value `header` (empty: none) is checked against it (Check). OK for the methods
  // open to everyone (health, reflection) without identifying anyone; else OK with *caller set.
  // `peer` names the client in the log (may be empty).
  grpc::Status Admit(std::string_view path, std::string_view header, std::string_view peer,
                     Caller* caller) const;
  // The check itself on an "authorization" value (`header`, empty: none) for a call needing
  // `access`: UNAUTHENTICATED (no or unknown token) or PERMISSION_DENIED (an analyst on a control
  // call); `rpc` names the call in the message.
  grpc::Status Check(std::string_view header, Access access, std::string_view rpc,
                     std::string_view peer, Caller* caller) const;

  // Who is calling, for a handler that needs to know (the audit's actor, the caps per token):
  // the token of the call's metadata, identified. Handlers never check access: the call was
  // admitted at its door. (Not an attachment of the gate's: gRPC's AuthContext is the
  // connection's, shared by every call on it, so a property the gate added for one call would
  // be seen by the next.) UNAUTHENTICATED only for a call that no door admitted (a server built
  // without the token gate, with tokens configured).
  grpc::Status CallerOf(const grpc::ServerContextBase& context, Caller* caller) const;

 private:
  std::vector<TokenConfig> tokens_;
};

}  // namespace brdf::daemon
