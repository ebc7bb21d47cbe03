// A JSON text written as it goes (no document held in memory), for exports whose arrays run to
// millions of numbers (the BiRD file: docs/bird-format.md). The caller says what comes next —
// an object's key, a value, the start or end of an object or array — and JsonOut puts the
// commas, quotes and escapes. Numbers are the shortest decimal form that reads back to the same
// double (number_text.h); a number that is not finite is the caller's error (JSON has no NaN)
// and is refused. Text is buffered and handed to the stream in pieces of about 64 KiB. Pure: it
// writes to the std::ostream it is given.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"

namespace brdf::exports {

class JsonOut {
 public:
  explicit JsonOut(std::ostream& out) : out_(out) {}
  JsonOut(const JsonOut&) = delete;
  JsonOut& operator=(const JsonOut&) = delete;

  void BeginObject();
  void EndObject();
  void BeginArray();
  void EndArray();
  // The next member's key (inside an object); the value follows.
  void Key(std::string_view key);
  void String(std::string_view text);
  // kInvalidArgument (remembered: Finish reports it) when `value` is not finite.
  void Number(double value);
  void Integer(std::int64_t value);

  // Key and value in one call.
  void Field(std::string_view key, std::string_view text);
  void Field(std::string_view key, const char* text) { Field(key, std::string_view(text)); }
  void Field(std::string_view key, double value);
  // {"value": value, "unit": unit}, the format's quantity with a unit.
  void ValueWithUnit(std::string_view key, double value, std::string_view unit);

  // Hands the rest of the text to the stream. The first error met: a non-finite number
  // (kInvalidArgument), unbalanced nesting (kInternal), the stream failing (kIoError).
  Status Finish();

 private:
  void BeforeValue();
  void Close(char bracket);
  void Flush();

  std::ostream& out_;
  std::string buffer_;
  std::vector<bool> has_member_;  // per open object or array: something written in it already
  bool after_key_ = false;        // a key was written; its value comes next
  Status error_;
};

}  // namespace brdf::exports
