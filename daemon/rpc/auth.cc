#include "daemon/rpc/auth.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "core/client_text.h"

namespace brdf::daemon {

bool ConstantTimeEquals(std::string_view a, std::string_view b) {
  const std::size_t n = std::max(a.size(), b.size());
  // Different lengths differ, but we still walk max(|a|, |b|) bytes so that the time taken says
  // nothing about the content.
  std::uint64_t diff = static_cast<std::uint64_t>(a.size() ^ b.size());
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0;
    const unsigned char y = i < b.size() ? static_cast<unsigned char>(b[i]) : 0;
    diff |= static_cast<std::uint64_t>(x ^ y);
  }
  // Read through a volatile so the compiler cannot turn the loop into an early-exit memcmp.
  volatile std::uint64_t result = diff;
  return result == 0;
}

Authenticator::Authenticator(std::vector<TokenConfig> tokens) : tokens_(std::move(tokens)) {}

namespace {

bool StartsWithBearer(std::string_view header) {
  static constexpr std::string_view kScheme = "bearer ";
  if (header.size() < kScheme.size()) return false;
  for (std::size_t i = 0; i < kScheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(header[i])) != kScheme[i]) return false;
  }
  return true;
}

}  // namespace

bool Authenticator::Identify(std::string_view header, Caller* caller, AuthFailure* failure) const {
  *failure = AuthFailure::kNone;
  if (tokens_.empty()) {
    *caller = Caller{Role::kOperator, "anonymous"};
    return true;
  }
  if (header.empty()) {
    *failure = AuthFailure::kMissing;
    return false;
  }
  if (header.size() > kMaxHeaderBytes || !StartsWithBearer(header)) {
    *failure = AuthFailure::kMalformed;
    return false;
  }
  std::string_view token = header.substr(7);
  while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
  while (!token.empty() && (token.back() == ' ' || token.back() == '\r')) token.remove_suffix(1);
  if (token.empty()) {
    *failure = AuthFailure::kMalformed;
    return false;
  }
  // Compare with every token: no early exit, so the time does not depend on which one matched.
  std::size_t match = tokens_.size();
  for (std::size_t i = 0; i < tokens_.size(); ++i) {
    const bool equal = ConstantTimeEquals(token, tokens_[i].token);
    match = equal && match == tokens_.size() ? i : match;
  }
  if (match == tokens_.size()) {
    *failure = AuthFailure::kUnknown;
    return false;
  }
  *caller = Caller{tokens_[match].role, tokens_[match].name};
  return true;
}

namespace {

std::string_view AuthorizationOf(const grpc::ServerContextBase& context) {
  const auto& metadata = context.client_metadata();
  auto it = metadata.find("authorization");
  if (it == metadata.end()) return {};
  return std::string_view(it->second.data(), it->second.size());
}

}  // namespace

grpc::Status Authenticator::Admit(std::string_view path, std::string_view header,
                                  std::string_view peer, Caller* caller) const {
  const std::optional<Access> access = MethodAccess(path);
  if (!access.has_value()) return grpc::Status::OK;
  return Check(header, *access, MethodName(path), peer, caller);
}

grpc::Status Authenticator::CallerOf(const grpc::ServerContextBase& context, Caller* caller) const {
  // Read access is all this grants: the call's door checked what the method needs.
  return Check(AuthorizationOf(context), Access::kRead, "call", context.peer(), caller);
}

grpc::Status Authenticator::Check(std::string_view header, Access access, std::string_view rpc,
                                  std::string_view peer, Caller* caller) const {
  AuthFailure failure = AuthFailure::kNone;
  if (!Identify(header, caller, &failure)) {
    std::string why;
    switch (failure) {
      case AuthFailure::kMissing:
        why = "no \"authorization\" metadata";
        break;
      case AuthFailure::kMalformed:
        why = "the \"authorization\" metadata is not \"Bearer <token>\"";
        break;
      default:
        why = "the bearer token is not one of this daemon's tokens";
        break;
    }
    // Never the token itself, not even a wrong one (it may be a real token of another system).
    spdlog::debug("{}: refused a call from {}: {}", rpc, peer.empty() ? "a client" : peer, why);
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        std::string(rpc) + ": " + why +
                            "; send \"authorization: Bearer <token>\" with a token from the "
                            "daemon's [[auth.tokens]] (brdfctl: --token or $BRDF_TOKEN)");
  }
  if (access == Access::kControl && caller->role != Role::kOperator) {
    spdlog::warn("{}: refused token \"{}\" (role {}) from {}: the call needs an operator", rpc,
                 caller->name, RoleName(caller->role), peer.empty() ? "a client" : peer);
    return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                        std::string(rpc) + ": token \"" + caller->name + "\" has the role " +
                            RoleName(caller->role) +
                            ", which may only read; this call needs an operator token");
  }
  return grpc::Status::OK;
}

std::optional<Access> MethodAccess(std::string_view path) {
  auto starts = [&](std::string_view prefix) { return path.substr(0, prefix.size()) == prefix; };
  if (starts("/grpc.health.v1.Health/") || starts("/grpc.reflection.")) return std::nullopt;
  static constexpr std::string_view kControlVerbs[] = {"SubmitPlan",   "StartSession",
                                                       "PauseSession", "ResumeSession",
                                                       "AbortSession", "AnswerPrompt"};
  if (starts("/brdf.v1.Control/")) {
    const std::string_view method = path.substr(std::string_view("/brdf.v1.Control/").size());
    for (std::string_view verb : kControlVerbs) {
      if (method == verb) return Access::kControl;
    }
  }
  return Access::kRead;
}

std::string MethodName(std::string_view path) {
  const std::size_t slash = path.rfind('/');
  std::string_view name = slash == std::string_view::npos ? path : path.substr(slash + 1);
  return PrintablePrefix(name, 64);
}

}  // namespace brdf::daemon
