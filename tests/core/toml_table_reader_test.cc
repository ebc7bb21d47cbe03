// core/toml/table_reader.h: typed getters with defaults, and every problem of a file (unknown
// keys, wrong types, values out of range, missing keys, syntax errors) reported one way: the
// file, the line and column, the dotted key, then what to do.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/toml/table_reader.h"

namespace brdf::toml_keys {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr const char* kAdvice = "fix the file (example.toml shows every key)";

// A file parsed for a test, with its problems.
struct Parsed {
  Problems problems{"settings x.toml", StatusCode::kConfigurationError, kAdvice};
  toml::table doc;

  explicit Parsed(std::string_view text) {
    Result<toml::table> parsed = problems.Parse(text, "x.toml");
    EXPECT_TRUE(parsed.ok()) << parsed.status().message();
    if (parsed.ok()) doc = std::move(parsed).value();
  }
  std::string Message() const { return problems.status().message(); }
};

TEST(TomlTableReader, GettersReadValuesAndAbsentKeysKeepTheirDefaults) {
  Parsed f(
      "name = \"rig 1\"\nfast = true\nunits = 3\nscale = 2\nratio = 0.5\n"
      "[meter]\nport = \"/dev/ttyUSB0\"\n");
  TableReader root(f.problems, &f.doc);
  std::string name, missing = "kept";
  bool fast = false;
  std::uint16_t units = 0;
  double scale = 0, ratio = 0, absent = 7;
  EXPECT_TRUE(root.String("name", name));
  EXPECT_FALSE(root.String("nothing", missing));
  EXPECT_TRUE(root.Bool("fast", fast));
  EXPECT_TRUE(root.Int("units", units, 1, 10));
  EXPECT_TRUE(root.Double("scale", scale));  // an integer is a number too
  EXPECT_TRUE(root.Double("ratio", ratio, 0, 1, /*lo_open=*/true));
  EXPECT_FALSE(root.Double("absent", absent));
  TableReader meter = root.Sub("meter");
  std::string port;
  EXPECT_TRUE(meter.String("port", port));
  meter.Finish();
  root.Finish();
  EXPECT_TRUE(f.problems.status().ok()) << f.Message();
  EXPECT_EQ(name, "rig 1");
  EXPECT_EQ(missing, "kept");
  EXPECT_TRUE(fast);
  EXPECT_EQ(units, 3);
  EXPECT_EQ(scale, 2.0);
  EXPECT_EQ(ratio, 0.5);
  EXPECT_EQ(absent, 7.0);
  EXPECT_EQ(port, "/dev/ttyUSB0");
}

TEST(TomlTableReader, AnUnknownKeyIsNamedWithItsLineAndTheKnownOnes) {
  Parsed f("rate = 1\n[meter]\nport = \"a\"\nbaud_rate = 9600\n");
  TableReader root(f.problems, &f.doc);
  int rate = 0;
  root.Int("rate", rate, 0, 10);
  TableReader meter = root.Sub("meter");
  std::string port;
  meter.String("port", port);
  meter.Allow({"baud"});
  meter.Finish();
  root.Finish();
  const Status st = f.problems.status();
  EXPECT_EQ(st.code(), StatusCode::kConfigurationError);
  EXPECT_THAT(st.message(),
              HasSubstr("settings x.toml: line 4, column 1: unknown key meter.baud_rate (known "
                        "here: baud, port)"));
  EXPECT_THAT(st.message(), HasSubstr("\nsettings x.toml: " + std::string(kAdvice)));
}

TEST(TomlTableReader, WrongTypesAndRangesNameTheKeyAndWhatItMustBe) {
  Parsed f(
      "baud = \"9600\"\nunit = 300\nflag = 1\nratio = 1.5\nlevel = \"loud\"\nname = \"\"\n"
      "nan_value = nan\nserver = 3\n");
  TableReader root(f.problems, &f.doc);
  int baud = 0, unit = 0;
  bool flag = false;
  double ratio = 0, nan_value = 0;
  std::string level, name;
  EXPECT_FALSE(root.Int("baud", baud, 1, 115200));
  EXPECT_FALSE(root.Int("unit", unit, 1, 247));
  EXPECT_FALSE(root.Bool("flag", flag));
  EXPECT_FALSE(root.Double("ratio", ratio, 0, 1, /*lo_open=*/true));
  EXPECT_FALSE(root.OneOf("level", level, {"info", "warn"}));
  EXPECT_FALSE(root.String("name", name));
  EXPECT_FALSE(root.Double("nan_value", nan_value));
  EXPECT_EQ(root.Table("server"), nullptr);
  root.Finish();
  const std::string m = f.Message();
  EXPECT_THAT(m, HasSubstr("line 1, column 8: baud: must be an integer, not a string"));
  EXPECT_THAT(m, HasSubstr("line 2, column 8: unit: 300 is outside 1 … 247"));
  EXPECT_THAT(m, HasSubstr("line 3, column 8: flag: must be true or false, not an integer"));
  EXPECT_THAT(m, HasSubstr("ratio: 1.5 is outside (0, 1]"));
  EXPECT_THAT(m, HasSubstr("level: \"loud\" is not one of \"info\", \"warn\""));
  EXPECT_THAT(m, HasSubstr("name: must not be empty"));
  EXPECT_THAT(m, HasSubstr("nan_value: must be a finite number"));
  EXPECT_THAT(m, HasSubstr("server: must be a table, not an integer"));
  EXPECT_THAT(m, Not(HasSubstr("unknown key")));  // every key was asked for
  EXPECT_EQ(baud, 0);                             // a wrong value leaves the default
}

TEST(TomlTableReader, RequiredKeysAndArraysOfTables) {
  Parsed f(
      "[[tokens]]\nname = \"a\"\n[[tokens]]\nrole = \"x\"\n[[tokens]]\nname = \"c\"\n"
      "extra = 1\n");
  TableReader root(f.problems, &f.doc);
  std::vector<std::string> names;
  root.ArrayOfTables("tokens", "name and role", [&](TableReader& t, std::size_t) {
    std::string name;
    if (t.Require("name", "name the client")) t.String("name", name);
    t.Allow({"role"});
    t.Finish();
    names.push_back(name);
  });
  root.Finish();
  EXPECT_EQ(names, (std::vector<std::string>{"a", "", "c"}));
  const std::string m = f.Message();
  EXPECT_THAT(m, HasSubstr("tokens[1].name: missing; name the client"));
  EXPECT_THAT(m, HasSubstr("line 7, column 1: unknown key tokens[2].extra"));

  Parsed g("tokens = [1]\nother = 2\n");
  TableReader r(g.problems, &g.doc);
  r.ArrayOfTables("tokens", "name and role", [](TableReader&, std::size_t) {});
  EXPECT_THAT(g.Message(), HasSubstr("tokens[0]: must be a table with name and role, not an "
                                     "integer"));
  Parsed h("tokens = 3\n");
  TableReader s(h.problems, &h.doc);
  s.ArrayOfTables("tokens", "name and role", [](TableReader&, std::size_t) {});
  EXPECT_THAT(h.Message(), HasSubstr("tokens: must be an array of tables ([[tokens]]), not an "
                                     "integer"));
}

TEST(TomlTableReader, AnAbsentTableReadsAsEmpty) {
  Parsed f("");
  TableReader root(f.problems, &f.doc);
  TableReader meter = root.Sub("meter");
  int baud = 9600;
  EXPECT_FALSE(meter.Int("baud", baud, 1, 115200));
  meter.Finish();
  root.Finish();
  EXPECT_TRUE(f.problems.empty());
  EXPECT_EQ(baud, 9600);
}

TEST(TomlTableReader, ASyntaxErrorNamesTheFileTheLineAndWhatToDo) {
  Problems problems("settings y.toml", StatusCode::kInvalidArgument, kAdvice);
  const Result<toml::table> parsed = problems.Parse("a = 1\nb = = 2\n", "y.toml");
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(parsed.status().message(), AllOf(HasSubstr("settings y.toml: line 2, column "),
                                               HasSubstr("not valid TOML"), HasSubstr(kAdvice)));
}

}  // namespace
}  // namespace brdf::toml_keys
