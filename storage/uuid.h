// Random (version 4, RFC 9562) UUIDs: sessions' global identity across rigs.
#pragma once

#include <string>
#include <string_view>

namespace brdf::storage {

// A new random UUID, lower-case with hyphens ("1b4e28ba-2fa1-4d3b-a3f5-ef19b5a7633b"), from the
// operating system's random source.
std::string NewUuid();

// True for a UUID written as NewUuid writes them (36 characters, lower-case hex, hyphens at 8,
// 13, 18 and 23).
bool IsUuid(std::string_view text);

}  // namespace brdf::storage
