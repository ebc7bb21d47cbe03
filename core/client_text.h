// Quoting what a client sent in an error message. A client's string (a service name, a field, a
// method in a URL) may be any size and hold any bytes; an error that repeats it whole would let
// a 100 KB name make a 100 KB gRPC trailer or HTTP body. Errors quote a short printable prefix.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace brdf {

// At most `max` bytes of `text`, each byte outside printable ASCII as '?', a longer text cut and
// marked with its full length: "abc... (102400 bytes)".
std::string PrintablePrefix(std::string_view text, std::size_t max = 64);

}  // namespace brdf
