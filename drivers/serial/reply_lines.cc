#include "drivers/serial/reply_lines.h"

#include <cstdio>

namespace brdf::drivers::serial {

std::vector<std::string> SplitReplyLines(std::string_view reply) {
  std::vector<std::string> lines;
  std::string current;
  for (std::size_t i = 0; i < reply.size(); ++i) {
    const char c = reply[i];
    if (c == '\r' || c == '\n') {
      if (c == '\r' && i + 1 < reply.size() && reply[i + 1] == '\n') ++i;
      if (!current.empty()) lines.push_back(std::move(current));
      current.clear();
    } else {
      current.push_back(c);
    }
  }
  if (!current.empty()) lines.push_back(std::move(current));
  return lines;
}

std::size_t CountCompleteLines(std::string_view bytes) {
  std::size_t count = 0;
  bool in_line = false;
  for (char c : bytes) {
    if (c == '\r' || c == '\n') {
      if (in_line) ++count;
      in_line = false;
    } else {
      in_line = true;
    }
  }
  return count;
}

bool EndsWithLineEnd(std::string_view bytes) {
  return !bytes.empty() && (bytes.back() == '\r' || bytes.back() == '\n');
}

std::string Printable(std::string_view bytes, std::size_t max_chars) {
  std::string out;
  for (char c : bytes) {
    if (out.size() >= max_chars) {
      out += "...";
      break;
    }
    const auto u = static_cast<unsigned char>(c);
    if (c == '\r') {
      out += "\\r";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (u >= 0x20 && u <= 0x7e) {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", u);
      out += hex;
    }
  }
  return out;
}

}  // namespace brdf::drivers::serial
