// How brdfctl reaches brdfd: one gRPC channel (plaintext or TLS) to the daemon's address, the three
// service stubs, and a ClientContext per call that carries the bearer token
// ("authorization: Bearer <token>") and, for unary calls, a deadline. The channel connects lazily;
// an unreachable daemon shows up as UNAVAILABLE on the first call.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <memory>
#include <string>

#include "brdf/v1/brdf.grpc.pb.h"
#include "core/status.h"

namespace brdf::ctl {

// Where and how to connect. Filled from flags and the environment (BRDF_ADDRESS, BRDF_TOKEN).
struct ClientOptions {
  std::string address = "127.0.0.1:50051";  // host:port, or unix:/path
  std::string token;                        // empty: no authorization metadata
  bool tls = false;
  std::string ca_file;    // PEM roots to trust (TLS); empty: the system's roots
  std::string cert_file;  // PEM client certificate chain (mutual TLS), with key_file
  std::string key_file;   // PEM client private key (mutual TLS)
  std::chrono::milliseconds timeout{10000};  // deadline of each unary call
};

class Client {
 public:
  // Builds the channel. kInvalidArgument when a TLS file cannot be read or cert/key come alone.
  static Result<std::unique_ptr<Client>> Create(const ClientOptions& options);

  v1::Control::Stub& control() { return *control_; }
  v1::Data::Stub& data() { return *data_; }
  v1::Interpolation::Stub& interpolation() { return *interpolation_; }
  // The channel itself, for a call made without the stubs (export_stream.h).
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }

  // A context for one unary call: token metadata and the configured deadline.
  std::unique_ptr<grpc::ClientContext> UnaryContext() const;
  // A context for a server stream: token metadata, no deadline (watch and follow run until the
  // session ends). Keep the context alive as long as the reader.
  std::unique_ptr<grpc::ClientContext> StreamContext() const;

  const ClientOptions& options() const { return options_; }

 private:
  explicit Client(const ClientOptions& options) : options_(options) {}
  void AddToken(grpc::ClientContext& context) const;

  ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Control::Stub> control_;
  std::unique_ptr<v1::Data::Stub> data_;
  std::unique_ptr<v1::Interpolation::Stub> interpolation_;
};

}  // namespace brdf::ctl
