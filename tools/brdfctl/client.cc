#include "tools/brdfctl/client.h"

#include <fstream>
#include <sstream>

namespace brdf::ctl {
namespace {

Result<std::string> ReadPem(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return InvalidArgument(what + " " + path + ": cannot open; give a readable PEM file");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (text.str().empty()) return InvalidArgument(what + " " + path + ": file is empty");
  return text.str();
}

}  // namespace

Result<std::unique_ptr<Client>> Client::Create(const ClientOptions& options) {
  std::unique_ptr<Client> client(new Client(options));
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (options.tls) {
    grpc::SslCredentialsOptions ssl;
    if (!options.ca_file.empty()) {
      BRDF_ASSIGN_OR_RETURN(std::string ca, ReadPem(options.ca_file, "--ca"));
      ssl.pem_root_certs = ca;
    }
    if (options.cert_file.empty() != options.key_file.empty()) {
      return InvalidArgument(
          "--cert and --key go together (a client certificate needs its private key)");
    }
    if (!options.cert_file.empty()) {
      BRDF_ASSIGN_OR_RETURN(std::string cert, ReadPem(options.cert_file, "--cert"));
      BRDF_ASSIGN_OR_RETURN(std::string key, ReadPem(options.key_file, "--key"));
      ssl.pem_cert_chain = cert;
      ssl.pem_private_key = key;
    }
    credentials = grpc::SslCredentials(ssl);
  } else {
    if (!options.ca_file.empty() || !options.cert_file.empty()) {
      return InvalidArgument("--ca, --cert and --key need --tls");
    }
    credentials = grpc::InsecureChannelCredentials();
  }
  grpc::ChannelArguments args;
  // Readings and batch answers carry spectra of 101 to 401 bands; allow large messages.
  args.SetMaxReceiveMessageSize(64 * 1024 * 1024);
  client->channel_ = grpc::CreateCustomChannel(options.address, credentials, args);
  client->control_ = v1::Control::NewStub(client->channel_);
  client->data_ = v1::Data::NewStub(client->channel_);
  client->interpolation_ = v1::Interpolation::NewStub(client->channel_);
  return client;
}

void Client::AddToken(grpc::ClientContext& context) const {
  if (!options_.token.empty()) context.AddMetadata("authorization", "Bearer " + options_.token);
}

std::unique_ptr<grpc::ClientContext> Client::UnaryContext() const {
  auto context = std::make_unique<grpc::ClientContext>();
  AddToken(*context);
  context->set_deadline(std::chrono::system_clock::now() + options_.timeout);
  return context;
}

std::unique_ptr<grpc::ClientContext> Client::StreamContext() const {
  auto context = std::make_unique<grpc::ClientContext>();
  AddToken(*context);
  return context;
}

}  // namespace brdf::ctl
