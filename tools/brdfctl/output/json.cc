#include "tools/brdfctl/output/json.h"

#include <google/protobuf/util/json_util.h>

namespace brdf::ctl {

std::string JsonLine(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = false;
  options.always_print_primitive_fields = true;
  std::string out;
  const auto status = google::protobuf::util::MessageToJsonString(message, &out, options);
  if (!status.ok()) {
    // Only invalid UTF-8 in a string field gets here; keep the line parsable.
    return R"({"brdfctlError":"cannot print )" + message.GetTypeName() + R"( as JSON"})";
  }
  return out;
}

void PrintJsonLine(std::ostream& out, const google::protobuf::Message& message) {
  out << JsonLine(message) << "\n";
  out.flush();
}

}  // namespace brdf::ctl
