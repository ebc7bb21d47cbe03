// JSON string literals in the exports' text files (the grid's .npy.json sidecar, the BiRD file):
// quotes, backslashes and control characters escaped (RFC 8259 §7: \" \\ \n \r \t, the other
// control characters as \u00XX); UTF-8 passes through unchanged.
#pragma once

#include <string>
#include <string_view>

namespace brdf::exports {

// Appends `text` as a JSON string literal, quotes included.
void AppendJsonString(std::string& out, std::string_view text);
// The same as a new string.
std::string JsonString(std::string_view text);

}  // namespace brdf::exports
