// JSON string literals, for every JSON text brdfd writes by hand (the exports' sidecars and BiRD
// file, the gateway's error bodies, brdf-sim's truth):
// quotes, backslashes and control characters escaped (RFC 8259 §7: \" \\ \n \r \t, the other
// control characters as \u00XX); UTF-8 passes through unchanged.
#pragma once

#include <string>
#include <string_view>

namespace brdf {

// Appends `text` as a JSON string literal, quotes included.
void AppendJsonString(std::string& out, std::string_view text);
// The same as a new string.
std::string JsonString(std::string_view text);

}  // namespace brdf
