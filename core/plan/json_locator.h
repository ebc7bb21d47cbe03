// Where things are in a JSON text, for error messages that an operator can act on: a syntax
// error with its line and column, and the line and column of the member at a field path.
// protobuf's JSON parser names the field of a bad value but not its place in the file, and the
// place of a syntax error only as an excerpt; this scanner supplies both. Strict RFC 8259 JSON.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace brdf::plan {

// 1-based; columns count characters (UTF-8 code points), not bytes.
struct TextPosition {
  int line = 1;
  int column = 1;
  friend bool operator==(const TextPosition&, const TextPosition&) = default;
};

// "sample_rotation.alpha.step" → "sampleRotation.alpha.step" (the proto JSON mapping's names);
// already lowerCamelCase segments and "[3]" indexes pass unchanged.
std::string ToJsonPath(std::string_view proto_path);

class JsonLocator {
 public:
  // Nesting deeper than this is refused as a syntax error.
  static constexpr int kMaxDepth = 64;

  // Scans `text`. On a syntax error, error() says what and where; Find() then knows the members
  // before the error only.
  explicit JsonLocator(std::string_view text);

  struct SyntaxError {
    TextPosition at;
    std::string message;  // e.g. "expected ',' or '}' after an object member"
  };
  const std::optional<SyntaxError>& error() const { return error_; }

  // Where the member (its key) or array element at `json_path` starts ("sampleFixed.targets[3]",
  // "sampleRotation.alpha.step"; keys written in snake_case are found too).
  std::optional<TextPosition> Find(std::string_view json_path) const;

 private:
  std::map<std::string, TextPosition> members_;
  std::optional<SyntaxError> error_;
  friend class JsonScanner;
};

}  // namespace brdf::plan
