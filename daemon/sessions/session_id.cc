#include "daemon/sessions/session_id.h"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <string>

namespace brdf::daemon {

Result<SessionId> ParseSessionId(const std::string& text, const std::string& field) {
  const bool digits =
      !text.empty() && text.size() <= 18 && std::all_of(text.begin(), text.end(), [](char ch) {
        return std::isdigit(static_cast<unsigned char>(ch));
      });
  if (!digits || std::stoll(text) <= 0) {
    // Echo at most a short, printable prefix: the message travels back in a gRPC trailer, and a
    // hostile megabyte-long id must not make the error itself too large to deliver.
    constexpr std::size_t kEchoBytes = 32;
    std::string shown;
    for (char ch : text.substr(0, kEchoBytes)) {
      shown += std::isprint(static_cast<unsigned char>(ch)) ? ch : '?';
    }
    if (text.size() > kEchoBytes) shown += "...";
    return InvalidArgument(field + ": \"" + shown + "\" (" + std::to_string(text.size()) +
                           " bytes) is not a session id (a positive number, as SubmitPlan "
                           "returned it)");
  }
  return static_cast<SessionId>(std::stoll(text));
}

}  // namespace brdf::daemon
