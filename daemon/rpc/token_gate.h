// The token gate: every call's bearer token is checked from its metadata, before gRPC reads the
// request message, so a call without a valid token never costs the daemon the memory of its body
// (up to kMaxReceiveMessageBytes). It is gRPC's per-call AuthMetadataProcessor, set on the
// server's credentials (TLS and plaintext alike), and applies Authenticator::Check with the
// access MethodAccess gives the call's path: UNAUTHENTICATED without a valid token,
// PERMISSION_DENIED for an analyst on a mutating Control verb; the health service and reflection
// pass without a token. Handlers that need the caller identify its token
// (Authenticator::CallerOf); they never check access again.
//
// Whatever reaches the services over gRPC goes through here: the HTTP gateway (issue 24) calls
// the same server over loopback with the client's bearer token, and gets the same refusals.
#pragma once

#include <grpcpp/security/auth_metadata_processor.h>

#include "daemon/rpc/auth.h"

namespace brdf::daemon {

class TokenGate final : public grpc::AuthMetadataProcessor {
 public:
  // `auth` must outlive the server the gate is set on.
  explicit TokenGate(const Authenticator& auth) : auth_(auth) {}

  // Runs on gRPC's transport thread: it only compares strings.
  bool IsBlocking() const override { return false; }

  grpc::Status Process(const InputMetadata& metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed, OutputMetadata* response) override;

 private:
  const Authenticator& auth_;
};

}  // namespace brdf::daemon
