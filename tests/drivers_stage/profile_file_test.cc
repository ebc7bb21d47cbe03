// Stage register profiles as files (drivers/stage/profile_file.h): every shipped file loads and
// holds the same registers as the maps compiled into brdfd before issue 21, a lab's own file is
// read with its ramp in the drive's unit, and a bad file is refused naming the file, the line,
// the key and what to do.
#include "drivers/stage/profile_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace brdf::drivers::stage {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// The register maps as brdfd compiled them in before issue 21 (register_profile.cc at 867d95c),
// written out field by field; the shipped files must reproduce every register and value.
RegisterField F(std::uint16_t a, int w) {
  return RegisterField{a, w};
}
CommandAction Pulse(std::uint32_t bits) {
  return {CommandAction::Kind::kPulseBits, {}, bits};
}
CommandAction Write(std::uint16_t a, std::uint32_t v) {
  return {CommandAction::Kind::kWriteValue, F(a, 1), v};
}

RegisterProfile CompiledAz() {
  RegisterProfile p;
  p.name = "az";
  p.verified_against_hardware = true;
  p.block_start = 0x0058;
  p.block_constants = {{F(0x0058, 2), 0, ""},
                       {F(0x0060, 2), 1'000'000, ""},
                       {F(0x0062, 2), 1'000'000, ""},
                       {F(0x0064, 2), 1000, ""}};
  p.operation_type = F(0x005A, 2);
  p.absolute_type = 1;
  p.position = F(0x005C, 2);
  p.speed = F(0x005E, 2);
  p.speed_scale = 1.0;
  p.trigger_style = TriggerStyle::kTriggerInBlock;
  p.trigger = F(0x0066, 2);
  p.trigger_value = 1;
  p.input_command = F(0x007C, 2);
  p.home = Pulse(1u << 4);
  p.stop = Pulse(1u << 5);
  p.alarm_reset = Pulse(1u << 7);
  p.status = F(0x007E, 2);
  p.status_bits = {1u << 5, 1u << 7, 1u << 8, 1u << 13, 1u << 14};
  p.alarm_code = F(0x0080, 2);
  p.feedback_position = F(0x00CC, 2);
  return p;
}

RegisterProfile CompiledLeadshine() {
  RegisterProfile p;
  p.name = "leadshine";
  p.block_start = 0x6200;
  p.operation_type = F(0x6200, 1);
  p.absolute_type = 1;
  p.position = F(0x6201, 2);
  p.speed = F(0x6203, 1);
  p.speed_scale = 60.0 / 10000.0;
  p.block_constants = {{F(0x6204, 1), 100, ""}, {F(0x6205, 1), 100, ""}};
  p.trigger_style = TriggerStyle::kWriteValueToRegister;
  p.trigger = F(0x6002, 1);
  p.trigger_value = 0x0010;
  p.home = Write(0x6002, 0x0020);
  p.stop = Write(0x6002, 0x0040);
  p.alarm_reset = Write(0x1801, 0x1111);
  p.status = F(0x1003, 1);
  p.status_bits = {0x0002, 0x0001, 0, 0x0004, 0x0020};
  p.alarm_code = F(0x2203, 1);
  p.feedback_position = F(0x602C, 2);
  return p;
}

RegisterProfile CompiledMoons() {
  RegisterProfile p;
  p.name = "moons";
  p.block_start = 27;
  p.block_constants = {{F(27, 1), 600, ""}, {F(28, 1), 600, ""}};
  p.speed = F(29, 1);
  p.speed_scale = 240.0 / 20000.0;
  p.position = F(30, 2);
  p.trigger_style = TriggerStyle::kOpcodeRegister;
  p.trigger = F(124, 1);
  p.trigger_value = 0x66;
  p.stop = Write(124, 0xE1);
  p.alarm_reset = Write(124, 0xBA);
  p.status = F(1, 1);
  p.status_bits = {0x0001, 0x0004 | 0x0200, 0, 0x0010, 0x0008};
  p.alarm_code = F(0, 1);
  p.feedback_position = F(4, 2);
  return p;
}

void ExpectField(const RegisterField& got, const RegisterField& want, const char* what) {
  EXPECT_EQ(got.words, want.words) << what;
  if (want.present()) {
    EXPECT_EQ(got.address, want.address) << what;
  }
}

void ExpectCommand(const CommandAction& got, const CommandAction& want, const char* what) {
  EXPECT_EQ(got.kind, want.kind) << what;
  EXPECT_EQ(got.value, want.value) << what;
  if (want.kind == CommandAction::Kind::kWriteValue) {
    ExpectField(got.field, want.field, what);
  }
}

void ExpectSameRegisters(const RegisterProfile& got, const RegisterProfile& want) {
  SCOPED_TRACE(want.name);
  EXPECT_EQ(got.name, want.name);
  EXPECT_EQ(got.verified_against_hardware, want.verified_against_hardware);
  EXPECT_EQ(got.word_order, want.word_order);
  EXPECT_EQ(got.block_start, want.block_start);
  ExpectField(got.operation_type, want.operation_type, "operation_type");
  if (want.operation_type.present()) {
    EXPECT_EQ(got.absolute_type, want.absolute_type);
  }
  ExpectField(got.position, want.position, "position");
  ExpectField(got.speed, want.speed, "speed");
  EXPECT_DOUBLE_EQ(got.speed_scale, want.speed_scale);
  ASSERT_EQ(got.block_constants.size(), want.block_constants.size());
  for (std::size_t i = 0; i < want.block_constants.size(); ++i) {
    ExpectField(got.block_constants[i].field, want.block_constants[i].field, "block constant");
    EXPECT_EQ(got.block_constants[i].value, want.block_constants[i].value)
        << got.block_constants[i].what;
  }
  EXPECT_EQ(got.trigger_style, want.trigger_style);
  ExpectField(got.trigger, want.trigger, "trigger");
  EXPECT_EQ(got.trigger_value, want.trigger_value);
  ExpectField(got.input_command, want.input_command, "input_command");
  ExpectCommand(got.home, want.home, "home");
  ExpectCommand(got.stop, want.stop, "stop");
  ExpectCommand(got.alarm_reset, want.alarm_reset, "alarm_reset");
  ExpectField(got.status, want.status, "status");
  EXPECT_EQ(got.status_bits.ready, want.status_bits.ready);
  EXPECT_EQ(got.status_bits.alarm, want.status_bits.alarm);
  EXPECT_EQ(got.status_bits.busy, want.status_bits.busy);
  EXPECT_EQ(got.status_bits.moving, want.status_bits.moving);
  EXPECT_EQ(got.status_bits.in_position, want.status_bits.in_position);
  ExpectField(got.alarm_code, want.alarm_code, "alarm_code");
  ExpectField(got.feedback_position, want.feedback_position, "feedback_position");
  const BlockSpan a = OperationBlockSpan(got);
  const BlockSpan b = OperationBlockSpan(want);
  EXPECT_EQ(a.start, b.start);
  EXPECT_EQ(a.count, b.count);
}

std::string ShippedPath(const std::string& name) {
  return std::string(BRDF_TEST_SOURCE_DIR) + "/deploy/stage-profiles/" + name + ".toml";
}

TEST(StageProfileFiles, EveryShippedFileLoadsAndHoldsTheRegistersCompiledInBefore) {
  EXPECT_EQ(BuiltinProfileNames(), (std::vector<std::string>{"az", "leadshine", "moons"}));
  const std::pair<const char*, RegisterProfile> expected[] = {
      {"az", CompiledAz()}, {"leadshine", CompiledLeadshine()}, {"moons", CompiledMoons()}};
  for (const auto& [name, want] : expected) {
    auto from_file = LoadProfileFile(ShippedPath(name));
    ASSERT_TRUE(from_file.ok()) << from_file.status().message();
    ExpectSameRegisters(*from_file, want);
    EXPECT_FALSE(from_file->source.empty()) << name << " names no manual";
    auto built_in = BuiltinProfile(name);
    ASSERT_TRUE(built_in.ok()) << built_in.status().message();
    ExpectSameRegisters(*built_in, want);
  }
  ExpectSameRegisters(RegisterProfile::AzDefault(), CompiledAz());
  ExpectSameRegisters(RegisterProfile::Leadshine(), CompiledLeadshine());
  ExpectSameRegisters(RegisterProfile::Moons(), CompiledMoons());
}

TEST(StageProfileFiles, TheBuiltInTextIsTheShippedFile) {
  for (const auto& name : BuiltinProfileNames()) {
    std::ifstream in(ShippedPath(name));
    const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(std::string(BuiltinProfileText(name)), file) << name;
  }
}

TEST(StageProfileFiles, RampsAreGivenInTheDrivesUnit) {
  const RegisterProfile az = RegisterProfile::AzDefault();
  EXPECT_EQ(az.ramp.unit, "kHz/s");
  EXPECT_DOUBLE_EQ(az.ramp.acceleration, 1000.0);
  // A lab whose AZ is set to the time unit: half a second to speed, 0.25 s to stop.
  std::string text(BuiltinProfileText("az"));
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("unit = \"kHz/s\"", "unit = \"s\"");
  replace("acceleration = 1000.0", "acceleration = 0.5");
  replace("deceleration = 1000.0", "deceleration = 0.25");
  auto p = ParseProfileText(text, "lab.toml");
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_EQ(p->block_constants.size(), 4u);
  EXPECT_EQ(p->block_constants[1].field.address, 0x0060);
  EXPECT_EQ(p->block_constants[1].value, 500);
  EXPECT_EQ(p->block_constants[2].field.address, 0x0062);
  EXPECT_EQ(p->block_constants[2].value, 250);
  EXPECT_THAT(p->block_constants[1].what, HasSubstr("0.5 s"));
}

// The az file with one line replaced (the line must exist).
std::string AzWith(const std::string& from, const std::string& to) {
  std::string text(BuiltinProfileText("az"));
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string Refusal(const std::string& text) {
  auto p = ParseProfileText(text, "/etc/brdfd/lab-stage.toml");
  EXPECT_FALSE(p.ok());
  if (p.ok()) return "";
  EXPECT_EQ(p.status().code(), StatusCode::kConfigurationError);
  EXPECT_THAT(p.status().message(), HasSubstr("/etc/brdfd/lab-stage.toml"));
  return p.status().message();
}

TEST(StageProfileFiles, BadFilesAreRefusedNamingTheFileLineKeyAndWhatToDo) {
  EXPECT_THAT(Refusal(AzWith("moving = 0x2000", "moving = \"bit 13\"")),
              AllOf(HasSubstr("status_bits.moving: must be an integer"), HasSubstr("line "),
                    HasSubstr("fix the file")));
  EXPECT_THAT(Refusal(AzWith("word_order = \"high_first\"", "word_order = \"little\"")),
              AllOf(HasSubstr("word_order: "), HasSubstr("\"high_first\", \"low_first\"")));
  EXPECT_THAT(Refusal(AzWith("in_position = 0x4000", "in_positon = 0x4000")),
              HasSubstr("unknown key status_bits.in_positon"));
  EXPECT_THAT(Refusal(AzWith("[feedback_position]", "[feedback]")),
              HasSubstr("unknown key feedback "));
  EXPECT_THAT(
      Refusal(AzWith("words = 2\n\n[feedback_position]", "words = 3\n\n[feedback_position]")),
      HasSubstr("alarm_code.words: 3 is outside 1 … 2"));
  EXPECT_THAT(Refusal(AzWith("acceleration = 1000.0", "acceleration = 5e6")),
              AllOf(HasSubstr("ramp.acceleration: "), HasSubstr("does not fit")));
  EXPECT_THAT(Refusal(AzWith("deceleration = 1000.0", "deceleration = -1")),
              HasSubstr("ramp.deceleration: "));
  EXPECT_THAT(Refusal(AzWith("block_start = 0x0058", "")), HasSubstr("block_start: missing"));
  EXPECT_THAT(Refusal(AzWith("kind = \"pulse_bits\"\nvalue = 0x0020", "kind = \"jump\"")),
              HasSubstr("stop.kind: "));
  // Valid TOML, but a map that cannot work: the validator's field, under the file's name.
  EXPECT_THAT(Refusal(AzWith("position = { address = 0x005C", "position = { address = 0x005A")),
              AllOf(HasSubstr("position.address"), HasSubstr("overlaps")));
  EXPECT_THAT(Refusal("name = \"x\"\n[status\n"),
              AllOf(HasSubstr("line 2"), HasSubstr("not valid TOML")));
}

TEST(StageProfileFiles, AFileThatCannotBeReadIsNamed) {
  auto p = LoadProfileFile("/nonexistent/brdf-stage.toml");
  ASSERT_FALSE(p.ok());
  EXPECT_THAT(p.status().message(),
              AllOf(HasSubstr("/nonexistent/brdf-stage.toml"), HasSubstr("profile_file")));
  auto unknown = BuiltinProfile("arcus");
  ASSERT_FALSE(unknown.ok());
  EXPECT_THAT(unknown.status().message(),
              AllOf(HasSubstr("az, leadshine, moons"), HasSubstr("profile_file")));
}

TEST(StageProfileFiles, ALabsOwnFileLoadsFromDisk) {
  const std::string path =
      ::testing::TempDir() + "/lab-profile-" + std::to_string(getpid()) + ".toml";
  {
    std::ofstream out(path);
    out << AzWith("word_order = \"high_first\"", "word_order = \"low_first\"");
  }
  auto p = LoadProfileFile(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_EQ(p->word_order, WordOrder::kLowFirst);
}

}  // namespace
}  // namespace brdf::drivers::stage
