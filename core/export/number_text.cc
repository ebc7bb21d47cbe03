#include "core/export/number_text.h"

#include <charconv>
#include <cmath>

namespace brdf::exports {

void AppendNumber(std::string& out, double value) {
  if (std::isnan(value)) {
    out += "nan";
    return;
  }
  if (std::isinf(value)) {
    out += value > 0 ? "inf" : "-inf";
    return;
  }
  char buf[32];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, r.ptr);
}

std::string FormatNumber(double value) {
  std::string s;
  AppendNumber(s, value);
  return s;
}

}  // namespace brdf::exports
