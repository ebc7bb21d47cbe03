#include "core/export/bird/json_out.h"

#include <cmath>

#include "core/export/number_text.h"
#include "core/json_text.h"

namespace brdf::exports {
namespace {

constexpr std::size_t kFlushBytes = 64 * 1024;

}  // namespace

void JsonOut::BeforeValue() {
  if (after_key_) {  // the value of the key just written
    after_key_ = false;
    return;
  }
  if (has_member_.empty()) return;
  if (has_member_.back()) buffer_ += ',';
  has_member_.back() = true;
}

void JsonOut::BeginObject() {
  BeforeValue();
  buffer_ += '{';
  has_member_.push_back(false);
}

void JsonOut::EndObject() {
  Close('}');
}

void JsonOut::BeginArray() {
  BeforeValue();
  buffer_ += '[';
  has_member_.push_back(false);
}

void JsonOut::EndArray() {
  Close(']');
}

void JsonOut::Close(char bracket) {
  if (has_member_.empty()) {
    if (error_.ok()) error_ = Internal("JsonOut: an object or array ended that was not begun");
    return;
  }
  has_member_.pop_back();
  buffer_ += bracket;
  Flush();
}

void JsonOut::Key(std::string_view key) {
  BeforeValue();
  AppendJsonString(buffer_, key);
  buffer_ += ':';
  after_key_ = true;
}

void JsonOut::String(std::string_view text) {
  BeforeValue();
  AppendJsonString(buffer_, text);
  Flush();
}

void JsonOut::Number(double value) {
  BeforeValue();
  if (!std::isfinite(value)) {
    if (error_.ok())
      error_ = InvalidArgument("JsonOut: a number that is not finite (JSON has none)");
    buffer_ += '0';
    return;
  }
  AppendNumber(buffer_, value);
  Flush();
}

void JsonOut::Integer(std::int64_t value) {
  BeforeValue();
  buffer_ += std::to_string(value);
  Flush();
}

void JsonOut::Field(std::string_view key, std::string_view text) {
  Key(key);
  String(text);
}

void JsonOut::Field(std::string_view key, double value) {
  Key(key);
  Number(value);
}

void JsonOut::ValueWithUnit(std::string_view key, double value, std::string_view unit) {
  Key(key);
  BeginObject();
  Field("value", value);
  Field("unit", unit);
  EndObject();
}

void JsonOut::Flush() {
  if (buffer_.size() < kFlushBytes) return;
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
}

Status JsonOut::Finish() {
  if (!error_.ok()) return error_;
  if (!has_member_.empty()) return Internal("JsonOut: an object or array was left open");
  buffer_ += '\n';
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
  out_.flush();
  if (!out_) return IoError("the JSON could not be written: the output stream failed");
  return Status();
}

}  // namespace brdf::exports
