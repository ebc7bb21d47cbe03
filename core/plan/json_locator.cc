#include "core/plan/json_locator.h"

#include <cctype>
#include <utility>

namespace brdf::plan {

std::string ToJsonPath(std::string_view proto_path) {
  std::string out;
  bool upper_next = false;
  for (char c : proto_path) {
    if (c == '_') {
      upper_next = true;
      continue;
    }
    if (upper_next && std::islower(static_cast<unsigned char>(c))) {
      out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    } else {
      out += c;
    }
    upper_next = false;
  }
  return out;
}

// A recursive-descent scanner that records the position of every member and element.
class JsonScanner {
 public:
  JsonScanner(std::string_view text, JsonLocator& out) : text_(text), out_(out) {}

  void Run() {
    SkipSpace();
    if (!Value("", 0)) return;
    SkipSpace();
    if (pos_ < text_.size()) Fail("unexpected text after the end of the JSON value");
  }

 private:
  bool AtEnd() const { return pos_ >= text_.size(); }
  char Peek() const { return AtEnd() ? '\0' : text_[pos_]; }

  void Advance() {
    const unsigned char c = static_cast<unsigned char>(text_[pos_++]);
    if (c == '\n') {
      ++at_.line;
      at_.column = 1;
    } else if ((c & 0xC0) != 0x80) {  // not a UTF-8 continuation byte
      ++at_.column;
    }
  }

  void SkipSpace() {
    while (!AtEnd() && (Peek() == ' ' || Peek() == '\t' || Peek() == '\n' || Peek() == '\r')) {
      Advance();
    }
  }

  bool Fail(std::string message) {
    if (!out_.error_) out_.error_ = JsonLocator::SyntaxError{at_, std::move(message)};
    return false;
  }

  bool Literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) {
      return Fail(
          "unexpected character; expected a value (object, array, string, number, "
          "true, false or null)");
    }
    for (std::size_t i = 0; i < word.size(); ++i) Advance();
    return true;
  }

  bool String(std::string* value) {
    Advance();  // opening quote
    while (true) {
      if (AtEnd()) return Fail("unterminated string");
      const char c = Peek();
      if (c == '"') {
        Advance();
        return true;
      }
      if (static_cast<unsigned char>(c) < 0x20) {
        return Fail("control character in a string; escape it (\\n, \\t, \\u00XX)");
      }
      if (c == '\\') {
        Advance();
        if (AtEnd()) return Fail("unterminated string");
        const char e = Peek();
        if (e == 'u') {
          Advance();
          for (int i = 0; i < 4; ++i) {
            if (AtEnd() || !std::isxdigit(static_cast<unsigned char>(Peek()))) {
              return Fail("bad \\u escape; give four hex digits");
            }
            Advance();
          }
          if (value) value->push_back('?');
          continue;
        }
        if (std::string_view("\"\\/bfnrt").find(e) == std::string_view::npos) {
          return Fail(std::string("bad escape \\") + e + " in a string");
        }
        if (value) value->push_back(e);
        Advance();
        continue;
      }
      if (value) value->push_back(c);
      Advance();
    }
  }

  bool Digits() {
    if (!std::isdigit(static_cast<unsigned char>(Peek()))) return Fail("malformed number");
    while (std::isdigit(static_cast<unsigned char>(Peek()))) Advance();
    return true;
  }

  bool Number() {
    if (Peek() == '-') Advance();
    if (Peek() == '0') {
      Advance();
      if (std::isdigit(static_cast<unsigned char>(Peek()))) {
        return Fail("malformed number: no leading zeros");
      }
    } else if (!Digits()) {
      return false;
    }
    if (Peek() == '.') {
      Advance();
      if (!Digits()) return false;
    }
    if (Peek() == 'e' || Peek() == 'E') {
      Advance();
      if (Peek() == '+' || Peek() == '-') Advance();
      if (!Digits()) return false;
    }
    return true;
  }

  bool Value(const std::string& path, int depth) {
    if (depth > JsonLocator::kMaxDepth) {
      return Fail("nested more than " + std::to_string(JsonLocator::kMaxDepth) + " levels deep");
    }
    if (AtEnd()) return Fail("unexpected end of the text; expected a value");
    const char c = Peek();
    if (c == '{') return Object(path, depth);
    if (c == '[') return Array(path, depth);
    if (c == '"') return String(nullptr);
    if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) return Number();
    if (c == 't') return Literal("true");
    if (c == 'f') return Literal("false");
    if (c == 'n') return Literal("null");
    return Fail("unexpected character '" + std::string(1, c) +
                "'; expected a value (object, array, string, number, true, false or null)");
  }

  bool Object(const std::string& path, int depth) {
    Advance();  // {
    SkipSpace();
    if (Peek() == '}') {
      Advance();
      return true;
    }
    while (true) {
      SkipSpace();
      if (Peek() != '"') return Fail("expected a member name in double quotes");
      const TextPosition key_at = at_;
      std::string key;
      if (!String(&key)) return false;
      const std::string member = path.empty() ? ToJsonPath(key) : path + "." + ToJsonPath(key);
      out_.members_.emplace(member, key_at);
      SkipSpace();
      if (Peek() != ':') return Fail("expected ':' after the member name \"" + key + "\"");
      Advance();
      SkipSpace();
      if (!Value(member, depth + 1)) return false;
      SkipSpace();
      if (Peek() == ',') {
        Advance();
        continue;
      }
      if (Peek() == '}') {
        Advance();
        return true;
      }
      return Fail("expected ',' or '}' after the member \"" + key + "\"");
    }
  }

  bool Array(const std::string& path, int depth) {
    Advance();  // [
    SkipSpace();
    if (Peek() == ']') {
      Advance();
      return true;
    }
    for (int i = 0;; ++i) {
      SkipSpace();
      const std::string element = path + "[" + std::to_string(i) + "]";
      out_.members_.emplace(element, at_);
      if (!Value(element, depth + 1)) return false;
      SkipSpace();
      if (Peek() == ',') {
        Advance();
        continue;
      }
      if (Peek() == ']') {
        Advance();
        return true;
      }
      return Fail("expected ',' or ']' after an array element");
    }
  }

  std::string_view text_;
  JsonLocator& out_;
  std::size_t pos_ = 0;
  TextPosition at_;
};

JsonLocator::JsonLocator(std::string_view text) {
  JsonScanner(text, *this).Run();
}

std::optional<TextPosition> JsonLocator::Find(std::string_view json_path) const {
  auto it = members_.find(ToJsonPath(json_path));
  if (it == members_.end()) return std::nullopt;
  return it->second;
}

}  // namespace brdf::plan
