// --json output: a reply as the protobuf JSON mapping on one line (lowerCamelCase names, enums by
// name, fields at their defaults included so that scripts can rely on them), one object per line
// for streams.
#pragma once

#include <google/protobuf/message.h>

#include <ostream>
#include <string>

namespace brdf::ctl {

std::string JsonLine(const google::protobuf::Message& message);

// Writes JsonLine(message) and a newline, and flushes (a stream's reader sees each event at once).
void PrintJsonLine(std::ostream& out, const google::protobuf::Message& message);

}  // namespace brdf::ctl
