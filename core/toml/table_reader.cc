#include "core/toml/table_reader.h"

#include <cmath>
#include <cstdio>
#include <utility>

namespace brdf::toml_keys {
namespace {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// "\"a\", \"b\", \"c\"".
std::string QuotedList(std::initializer_list<std::string_view> items) {
  std::string out;
  for (std::string_view s : items) {
    if (!out.empty()) out += ", ";
    out += "\"" + std::string(s) + "\"";
  }
  return out;
}

std::string Position(const toml::source_region& where) {
  if (where.begin.line == 0) return "";
  return "line " + std::to_string(where.begin.line) + ", column " +
         std::to_string(where.begin.column) + ": ";
}

}  // namespace

const char* TypeName(toml::node_type type) {
  switch (type) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number with a fraction";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date or time";
  }
}

// ---- Problems ----

Problems::Problems(std::string file, StatusCode code, std::string advice)
    : file_(std::move(file)), code_(code), advice_(std::move(advice)) {}

Result<toml::table> Problems::Parse(std::string_view text, std::string_view path) const {
  std::string message;
  try {
    return toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    message =
        file_ + ": " + Position(e.source()) + "not valid TOML: " + std::string(e.description());
  } catch (const std::exception& e) {
    message = file_ + ": cannot parse: " + e.what();
  }
  if (!advice_.empty()) message += "\n" + file_ + ": " + advice_;
  return Status(code_, message);
}

void Problems::AddLine(const toml::source_region& where, const std::string& text) {
  lines_.push_back(file_ + ": " + Position(where) + text);
}

void Problems::Add(const toml::source_region& where, std::string_view key,
                   std::string_view problem) {
  AddLine(where, std::string(key) + ": " + std::string(problem));
}

void Problems::AddUnknown(const toml::source_region& where, std::string_view key,
                          std::string_view known) {
  AddLine(where, "unknown key " + std::string(key) + " (known here: " + std::string(known) + ")");
}

Status Problems::status() const {
  if (lines_.empty()) return Status::Ok();
  std::string message;
  for (const std::string& line : lines_) message += (message.empty() ? "" : "\n") + line;
  if (!advice_.empty()) message += "\n" + file_ + ": " + advice_;
  return Status(code_, message);
}

// ---- TableReader: where keys are ----

TableReader::TableReader(Problems& problems, const toml::table* table, std::string path)
    : problems_(&problems), table_(table), path_(std::move(path)) {}

std::string TableReader::KeyPath(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

toml::source_region TableReader::where() const {
  return table_ != nullptr ? table_->source() : toml::source_region{};
}

const toml::node* TableReader::Node(std::string_view key) {
  known_.emplace(key);
  return table_ != nullptr ? table_->get(key) : nullptr;
}

void TableReader::Allow(std::initializer_list<std::string_view> keys) {
  for (std::string_view k : keys) known_.emplace(k);
}

void TableReader::Issue(std::string_view key, std::string_view problem) {
  const toml::node* n = Node(key);
  problems_->Add(n != nullptr ? n->source() : where(), KeyPath(key), problem);
}

bool TableReader::Require(std::string_view key, std::string_view hint) {
  if (Node(key) != nullptr) return true;
  problems_->Add(where(), KeyPath(key),
                 hint.empty() ? std::string("missing") : "missing; " + std::string(hint));
  return false;
}

bool TableReader::WrongType(const toml::node& node, std::string_view key, std::string_view wanted) {
  problems_->Add(node.source(), KeyPath(key),
                 "must be " + std::string(wanted) + ", not " + TypeName(node.type()));
  return false;
}

void TableReader::Finish() {
  if (table_ == nullptr) return;
  std::string known;
  for (const std::string& k : known_) known += (known.empty() ? "" : ", ") + k;
  for (const auto& [key, node] : *table_) {
    if (known_.count(key.str()) == 0)
      problems_->AddUnknown(key.source(), KeyPath(key.str()), known);
  }
}

// ---- TableReader: scalars ----

bool TableReader::Bool(std::string_view key, bool& out) {
  const toml::node* n = Node(key);
  if (n == nullptr) return false;
  if (!n->is_boolean()) return WrongType(*n, key, "true or false");
  out = n->as_boolean()->get();
  return true;
}

bool TableReader::Int64(std::string_view key, std::int64_t& out, std::int64_t lo, std::int64_t hi) {
  const toml::node* n = Node(key);
  if (n == nullptr) return false;
  if (!n->is_integer()) return WrongType(*n, key, "an integer");
  const std::int64_t v = n->as_integer()->get();
  if (v < lo || v > hi) {
    Issue(key,
          std::to_string(v) + " is outside " + std::to_string(lo) + " … " + std::to_string(hi));
    return false;
  }
  out = v;
  return true;
}

bool TableReader::Double(std::string_view key, double& out) {
  return Double(key, out, -HUGE_VAL, HUGE_VAL);
}

bool TableReader::Double(std::string_view key, double& out, double lo, double hi, bool lo_open) {
  const toml::node* n = Node(key);
  if (n == nullptr) return false;
  if (!n->is_number()) return WrongType(*n, key, "a number");
  const double v =
      n->is_integer() ? static_cast<double>(n->as_integer()->get()) : n->as_floating_point()->get();
  if (!std::isfinite(v)) {
    Issue(key, "must be a finite number, not " + Num(v));
    return false;
  }
  if ((lo_open ? v <= lo : v < lo) || v > hi) {
    Issue(key, Num(v) + " is outside " + (lo_open ? "(" : "[") + Num(lo) + ", " + Num(hi) + "]");
    return false;
  }
  out = v;
  return true;
}

bool TableReader::String(std::string_view key, std::string& out, Empty empty) {
  const toml::node* n = Node(key);
  if (n == nullptr) return false;
  if (!n->is_string()) return WrongType(*n, key, "a string");
  const std::string& v = n->as_string()->get();
  if (v.empty() && empty == Empty::kRefused) {
    Issue(key, "must not be empty");
    return false;
  }
  out = v;
  return true;
}

bool TableReader::OneOf(std::string_view key, std::size_t& index,
                        std::initializer_list<std::string_view> choices) {
  std::string v;
  if (!String(key, v, Empty::kAllowed)) return false;
  std::size_t i = 0;
  for (std::string_view c : choices) {
    if (v == c) {
      index = i;
      return true;
    }
    ++i;
  }
  Issue(key, "\"" + v + "\" is not one of " + QuotedList(choices));
  return false;
}

bool TableReader::OneOf(std::string_view key, std::string& out,
                        std::initializer_list<std::string_view> choices) {
  std::size_t index = 0;
  if (!OneOf(key, index, choices)) return false;
  out = std::string(*(choices.begin() + index));
  return true;
}

// ---- TableReader: tables and arrays ----

const toml::table* TableReader::Table(std::string_view key, std::string_view what) {
  const toml::node* n = Node(key);
  if (n == nullptr) return nullptr;
  if (!n->is_table()) {
    WrongType(*n, key, what);
    return nullptr;
  }
  return n->as_table();
}

TableReader TableReader::Sub(std::string_view key, std::string_view what) {
  const toml::table* table = Table(key, what);
  return TableReader(*problems_, table, KeyPath(key));
}

const toml::array* TableReader::Array(std::string_view key, std::string_view what) {
  const toml::node* n = Node(key);
  if (n == nullptr) return nullptr;
  if (!n->is_array()) {
    WrongType(*n, key, what);
    return nullptr;
  }
  return n->as_array();
}

void TableReader::ArrayOfTables(
    std::string_view key, std::string_view element,
    const std::function<void(TableReader& table, std::size_t index)>& read) {
  const toml::array* list = Array(key, "an array of tables ([[" + KeyPath(key) + "]])");
  if (list == nullptr) return;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const toml::node& n = *list->get(i);
    const std::string path = KeyPath(key) + "[" + std::to_string(i) + "]";
    if (!n.is_table()) {
      problems_->Add(
          n.source(), path,
          "must be a table with " + std::string(element) + ", not " + TypeName(n.type()));
      continue;
    }
    TableReader table(*problems_, n.as_table(), path);
    read(table, i);
  }
}

}  // namespace brdf::toml_keys
