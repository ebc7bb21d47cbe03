// Reading a parsed TOML file key by key, with every problem reported one way, wherever the file
// comes from (brdfd's configuration, a stage register profile, brdf-sim's settings):
//   <file>: line L, column C: <dotted.key>: <what is wrong>
//   <file>: line L, column C: unknown key <dotted.key> (known here: <the table's keys>)
//   <file>: <what to do>
// A file is refused once, naming every bad key (one line each), then what to do about it. A key
// a reader was not asked for is an error, never silently ignored: a typo must not fall back to a
// default.
//
//   toml_keys::Problems problems("config " + path, StatusCode::kConfigurationError,
//                                "fix the file (brdfd.example.toml shows every key)");
//   BRDF_ASSIGN_OR_RETURN(const toml::table doc, problems.Parse(text, path));
//   toml_keys::TableReader root(problems, &doc);
//   toml_keys::TableReader meter = root.Sub("meter");
//   meter.Int("baud", config.baud, 1200, 115200);  // absent: the default stays
//   meter.Finish();                                 // the keys no getter named are unknown
//   root.Finish();
//   BRDF_RETURN_IF_ERROR(problems.status());
//
// Pure: works on text and parsed tables; reading the file is the caller's.
#pragma once

#include <toml++/toml.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/status.h"

namespace brdf::toml_keys {

// The problems of one file, and how that kind of file reports them.
class Problems {
 public:
  // `file` names the file in every line ("config /etc/brdfd/brdfd.toml", "stage profile file
  // x.toml"); a refusal carries `code`; `advice` says what to do, once, after the problems.
  Problems(std::string file, StatusCode code, std::string advice);

  // Parses `text`. A syntax error is refused at once: "<file>: line L, column C: not valid TOML:
  // <toml++'s reason>" and the advice. `path` names the text in toml++'s source regions.
  Result<toml::table> Parse(std::string_view text, std::string_view path) const;

  // Notes "<key>: <problem>" at `where` (without a position when `where` has none).
  void Add(const toml::source_region& where, std::string_view key, std::string_view problem);
  // Notes "unknown key <key> (known here: <known>)" at `where`.
  void AddUnknown(const toml::source_region& where, std::string_view key, std::string_view known);

  bool empty() const { return lines_.empty(); }
  // OK when there is no problem; otherwise a Status of `code`: every problem, one per line, then
  // "<file>: <advice>".
  Status status() const;

 private:
  void AddLine(const toml::source_region& where, const std::string& text);

  std::string file_;
  StatusCode code_;
  std::string advice_;
  std::vector<std::string> lines_;
};

// Whether an empty string is a value or a mistake.
enum class Empty { kRefused, kAllowed };

// The keys of one table. Each getter marks its key as known; Finish() reports the table's other
// keys as unknown. A getter returns true when the key is present and valid (`out` updated), and
// false when it is absent (`out` keeps its default) or wrong (the problem noted, `out` kept).
class TableReader {
 public:
  // `table` may be null: an absent table reads as empty. `path` is its dotted path ("" for the
  // document itself, "stage.axes", "auth.tokens[0]").
  TableReader(Problems& problems, const toml::table* table, std::string path = "");

  const toml::table* table() const { return table_; }
  // "<path>.<key>", or "<key>" for the document.
  std::string KeyPath(std::string_view key) const;
  // The table's place in the file (none for an absent table).
  toml::source_region where() const;

  // The node at `key` (known from now on), or nullptr when absent.
  const toml::node* Node(std::string_view key);
  // Keys the table may hold that no getter reads (or reads only sometimes): not unknown.
  void Allow(std::initializer_list<std::string_view> keys);
  // Notes "<path>.<key>: <problem>" at the key's value, or at the table when the key is absent.
  void Issue(std::string_view key, std::string_view problem);
  // True when `key` is present; otherwise notes "<path>.<key>: missing[; <hint>]" at the table.
  bool Require(std::string_view key, std::string_view hint = "");

  bool Bool(std::string_view key, bool& out);
  // An integer in [lo, hi] ("3 is outside 1 … 2"), stored into any integer type that holds it.
  template <typename T>
  requires std::is_integral_v<T>
  bool Int(std::string_view key, T& out, std::int64_t lo, std::int64_t hi) {
    std::int64_t v = 0;
    if (!Int64(key, v, lo, hi)) return false;
    out = static_cast<T>(v);
    return true;
  }
  // A finite number (an integer or a float).
  bool Double(std::string_view key, double& out);
  // A finite number in [lo, hi], or (lo, hi] with lo_open ("1.5 is outside (0, 1]").
  bool Double(std::string_view key, double& out, double lo, double hi, bool lo_open = false);
  bool String(std::string_view key, std::string& out, Empty empty = Empty::kRefused);
  // A string among `choices` ("\"x\" is not one of \"a\", \"b\""): the string, or its index.
  bool OneOf(std::string_view key, std::string& out,
             std::initializer_list<std::string_view> choices);
  bool OneOf(std::string_view key, std::size_t& index,
             std::initializer_list<std::string_view> choices);

  // The table at `key`, or nullptr when absent or not a table ("must be <what>, not …").
  const toml::table* Table(std::string_view key, std::string_view what = "a table");
  // A reader of the table at `key` (empty when absent or not a table), for "<path>.<key>".
  TableReader Sub(std::string_view key, std::string_view what = "a table");
  // The array at `key`, or nullptr when absent or not an array ("must be <what>, not …").
  const toml::array* Array(std::string_view key, std::string_view what = "an array");
  // Each table of the array of tables at `key` ([[key]]), read by `read` with the path
  // "<key>[i]" and its index; an element that is not a table is noted as not being `element`
  // ("auth.tokens[1]: must be a table with name, token and role, not a string").
  void ArrayOfTables(std::string_view key, std::string_view element,
                     const std::function<void(TableReader& table, std::size_t index)>& read);

  // Notes every key of the table that no getter, Node or Allow named, with the known ones.
  void Finish();

 private:
  bool Int64(std::string_view key, std::int64_t& out, std::int64_t lo, std::int64_t hi);
  bool WrongType(const toml::node& node, std::string_view key, std::string_view wanted);

  Problems* problems_;
  const toml::table* table_;
  std::string path_;
  std::set<std::string, std::less<>> known_;
};

// "a string", "an integer", "a number with a fraction", "a table", … for messages.
const char* TypeName(toml::node_type type);

}  // namespace brdf::toml_keys
