#include "daemon/rpc/token_gate.h"

#include <optional>
#include <string_view>

namespace brdf::daemon {

grpc::Status TokenGate::Process(const InputMetadata& metadata, grpc::AuthContext* /*context*/,
                                OutputMetadata* /*consumed*/, OutputMetadata* /*response*/) {
  std::string_view path;
  std::string_view header;
  for (const auto& [key, value] : metadata) {
    const std::string_view k(key.data(), key.size());
    if (k == ":path") path = std::string_view(value.data(), value.size());
    if (k == "authorization") header = std::string_view(value.data(), value.size());
  }
  Caller caller;
  return auth_.Admit(path, header, "", &caller);
}

}  // namespace brdf::daemon
