// brdf-sim's configuration: defaults, the TOML file, the flags over it, and the checks.
#include "tools/brdf-sim/sim_config.h"

#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/test_env.h"

namespace brdf::sim {
namespace {

// Parses `args` the way main does: file first (if --config is among them), then the flags.
Status ParseLikeMain(std::vector<std::string> args, SimConfig& config) {
  args.insert(args.begin(), "brdf-sim");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  if (auto path = FindConfigPath(static_cast<int>(argv.size()), argv.data())) {
    BRDF_RETURN_IF_ERROR(LoadConfigFile(*path, config));
  }
  CLI::App app("brdf-sim");
  AddRunFlags(app, config);
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return InvalidArgument(e.what());
  }
  FinishFlags(app, config);
  return ValidateConfig(config);
}

TEST(SimConfigTest, DefaultsArePlausibleAndValid) {
  SimConfig c;
  EXPECT_TRUE(ValidateConfig(c).ok());
  EXPECT_EQ(c.time_scale, 1.0);
  EXPECT_EQ(c.modbus_port, 0);
  EXPECT_TRUE(c.detector_arm);
  EXPECT_TRUE(c.pacing);
  EXPECT_EQ(c.fifo_bytes, 14);  // a 16550 UART's receive FIFO
  EXPECT_EQ(c.mounted, MountedTarget::kSample);
  EXPECT_EQ(c.axes[kAlphaAxis].min_deg, 0);
  EXPECT_EQ(c.axes[kAlphaAxis].max_deg, 90);
  EXPECT_EQ(c.axes[kDeltaAxis].max_deg, 180);
  for (const AxisSettings& a : c.axes) EXPECT_GT(a.home_speed_deg_s, 0);
}

TEST(SimConfigTest, FlagsSetFields) {
  SimConfig c;
  ASSERT_TRUE(ParseLikeMain({"--time-scale",
                             "50",
                             "--seed",
                             "9",
                             "--modbus-port",
                             "1502",
                             "--rtu",
                             "--no-detector-arm",
                             "--no-pacing",
                             "--fifo-bytes",
                             "1",
                             "--wake-window",
                             "2.5",
                             "--anisotropic",
                             "--mounted",
                             "white",
                             "--beta-home-speed",
                             "40",
                             "--gamma-min",
                             "-90"},
                            c)
                  .ok());
  EXPECT_EQ(c.time_scale, 50);
  EXPECT_EQ(c.optics.seed, 9u);
  EXPECT_EQ(c.modbus_port, 1502);
  EXPECT_TRUE(c.rtu);
  EXPECT_FALSE(c.detector_arm);
  EXPECT_FALSE(c.pacing);
  EXPECT_EQ(c.fifo_bytes, 1);
  EXPECT_EQ(c.wake_window_s, 2.5);
  EXPECT_TRUE(c.optics.anisotropic);
  EXPECT_EQ(c.mounted, MountedTarget::kWhite);
  EXPECT_EQ(c.axes[kBetaAxis].home_speed_deg_s, 40);
  EXPECT_EQ(c.axes[kGammaAxis].min_deg, -90);

  SimConfig manual;
  ASSERT_TRUE(ParseLikeMain({"--no-detector-arm", "--manual-delta", "45"}, manual).ok());
  EXPECT_FALSE(manual.detector_arm);
  EXPECT_EQ(manual.manual_delta_deg, 45);
  SimConfig bad;
  EXPECT_FALSE(ParseLikeMain({"--manual-delta", "200"}, bad).ok());
}

TEST(SimConfigTest, FaultFlagsMirrorTheFaultStructs) {
  SimConfig c;
  ASSERT_TRUE(
      ParseLikeMain({"--serial-silent", "--serial-garbage-next", "2", "--serial-truncate-next", "3",
                     "--serial-quality-code", "18", "--serial-vanish-seconds", "1.5",
                     "--modbus-exception-code", "6", "--modbus-exception-count", "4",
                     "--modbus-late-reply-ms", "800", "--modbus-drop-connection",
                     "--modbus-alarm-mid-move", "--modbus-stall"},
                    c)
          .ok());
  EXPECT_TRUE(c.serial_faults.silent);
  EXPECT_EQ(c.serial_faults.garbage_next, 2);
  EXPECT_EQ(c.serial_faults.truncate_next, 3);
  EXPECT_EQ(c.serial_faults.quality_code, 18);
  EXPECT_EQ(c.serial_faults.quality_count, 1);  // a code without a count: the next one
  EXPECT_EQ(c.serial_faults.vanish_seconds, 1.5);
  EXPECT_EQ(c.modbus_faults.exception_code, 6);
  EXPECT_EQ(c.modbus_faults.exception_count, 4);
  EXPECT_EQ(c.modbus_faults.late_reply_ms, 800);
  EXPECT_EQ(c.modbus_faults.late_count, 1);
  EXPECT_TRUE(c.modbus_faults.drop_connection);
  EXPECT_TRUE(c.modbus_faults.alarm_mid_move);
  EXPECT_TRUE(c.modbus_faults.stall);
}

TEST(SimConfigTest, FileIsReadAndFlagsOverrideIt) {
  testing::TempDir dir;
  ASSERT_FALSE(dir.path().empty()) << dir.error();
  const auto path = dir.file("sim.toml");
  std::ofstream(path) << R"(
time_scale = 20
seed = 5
mounted = "dark"
[modbus]
port = 1600
[pr650]
pacing = false
fifo_bytes = 62
[stage]
detector_arm = false
[stage.alpha]
home_speed_deg_s = 10
max_deg = 80
[faults.serial]
quality_code = 29
quality_count = 3
[optics]
ambient_radiance = 1e-5
[optics.lamp]
color_temperature_k = 3000
)";
  SimConfig c;
  ASSERT_TRUE(ParseLikeMain({"--config", path.string(), "--time-scale", "40"}, c).ok());
  EXPECT_EQ(c.time_scale, 40);  // the flag wins
  EXPECT_EQ(c.optics.seed, 5u);
  EXPECT_EQ(c.mounted, MountedTarget::kDark);
  EXPECT_EQ(c.modbus_port, 1600);
  EXPECT_FALSE(c.pacing);
  EXPECT_EQ(c.fifo_bytes, 62);
  EXPECT_FALSE(c.detector_arm);
  EXPECT_EQ(c.axes[kAlphaAxis].home_speed_deg_s, 10);
  EXPECT_EQ(c.axes[kAlphaAxis].max_deg, 80);
  EXPECT_EQ(c.axes[kAlphaAxis].min_deg, 0);  // untouched
  EXPECT_EQ(c.serial_faults.quality_code, 29);
  EXPECT_EQ(c.serial_faults.quality_count, 3);
  EXPECT_EQ(c.optics.ambient_radiance, 1e-5);
  EXPECT_EQ(c.optics.lamp.color_temperature_k, 3000);
  EXPECT_EQ(c.config_path, path.string());
}

TEST(SimConfigTest, FileErrorsNameTheKey) {
  SimConfig c;
  Status unknown = LoadConfigString("[stage.alpha]\nsped_deg_s = 3\n", "x.toml", c);
  EXPECT_EQ(unknown.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(unknown.message().find("stage.alpha.sped_deg_s"), std::string::npos)
      << unknown.message();
  Status type = LoadConfigString("time_scale = \"fast\"\n", "x.toml", c);
  EXPECT_NE(type.message().find("time_scale"), std::string::npos) << type.message();
  Status syntax = LoadConfigString("time_scale = = 3\n", "x.toml", c);
  EXPECT_NE(syntax.message().find("x.toml: line 1"), std::string::npos) << syntax.message();
  Status mounted = LoadConfigString("mounted = \"grey\"\n", "x.toml", c);
  EXPECT_NE(mounted.message().find("grey"), std::string::npos) << mounted.message();
  // A failed load leaves the configuration as it was.
  EXPECT_TRUE(LoadConfigString("seed = 3\n[modbus]\nport = \"x\"\n", "x.toml", c).code() ==
              StatusCode::kInvalidArgument);
  EXPECT_EQ(c.optics.seed, SimConfig().optics.seed);
  EXPECT_EQ(LoadConfigFile("/nonexistent/brdf-sim.toml", c).code(), StatusCode::kNotFound);
}

TEST(SimConfigTest, ValidationRejectsImpossibleSettings) {
  auto invalid = [](auto mutate) {
    SimConfig c;
    mutate(c);
    return ValidateConfig(c).code() == StatusCode::kInvalidArgument;
  };
  EXPECT_TRUE(invalid([](SimConfig& c) { c.time_scale = 0; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.modbus_port = 70000; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.axes[kBetaAxis].home_speed_deg_s = -1; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.axes[kAlphaAxis].min_deg = 95; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.serial_faults.quality_code = 123; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.optics.noise_scale = -1; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.log_level = "loud"; }));
  EXPECT_TRUE(invalid([](SimConfig& c) { c.fifo_bytes = 0; }));
  SimConfig c;
  EXPECT_FALSE(ParseLikeMain({"--mounted", "grey"}, c).ok());
  EXPECT_FALSE(ParseLikeMain({"--fifo-bytes", "0"}, c).ok());
}

TEST(SimConfigTest, DriveAndMeterSettingsFromTheFileAndFlags) {
  SimConfig c;
  EXPECT_EQ(StageFunctionCodes(c), (FunctionCodes{3, 6, 8, 16}));  // the AZ's by default
  EXPECT_EQ(StageWordOrder(c), SimWordOrder::kHighFirst);
  EXPECT_EQ(StageRampUnit(c), SimRampUnit::kKhzPerSecond);
  EXPECT_FALSE(c.m0_reply_is_quality);
  ASSERT_TRUE(LoadConfigString(R"([stage]
function_codes = "moons"
word_order = "lower_first"
ramp_unit = "s"
[pr650]
d5_header_bare_cr = true
m0_reply_is_quality = true
)",
                               "test.toml", c)
                  .ok());
  ASSERT_TRUE(ValidateConfig(c).ok());
  EXPECT_EQ(StageFunctionCodes(c), (FunctionCodes{3, 4, 6, 16}));
  EXPECT_EQ(StageWordOrder(c), SimWordOrder::kLowFirst);
  EXPECT_EQ(StageRampUnit(c), SimRampUnit::kSeconds);
  EXPECT_TRUE(c.d5_header_bare_cr);
  EXPECT_TRUE(c.m0_reply_is_quality);

  SimConfig f;
  ASSERT_TRUE(ParseLikeMain({"--stage-function-codes", "3,16", "--stage-word-order", "lower_first",
                             "--stage-ramp-unit", "ms_per_khz", "--pr650-bare-cr-header",
                             "--pr650-m0-quality"},
                            f)
                  .ok());
  EXPECT_EQ(StageFunctionCodes(f), (FunctionCodes{3, 16}));
  EXPECT_EQ(StageRampUnit(f), SimRampUnit::kMsPerKhz);
  EXPECT_TRUE(f.d5_header_bare_cr);

  for (const auto& bad :
       std::vector<std::vector<std::string>>{{"--stage-function-codes", "3,7"},
                                             {"--stage-word-order", "middle_endian"},
                                             {"--stage-ramp-unit", "rpm"}}) {
    SimConfig b;
    const Status s = ParseLikeMain(bad, b);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << bad[0];
    EXPECT_NE(s.message().find(bad[0]), std::string::npos) << s.message();
  }
}

TEST(SimConfigTest, FindConfigPathAcceptsBothSpellings) {
  const char* a[] = {"brdf-sim", "--seed", "1", "--config", "a.toml"};
  const char* b[] = {"brdf-sim", "--config=b.toml"};
  const char* none[] = {"brdf-sim", "--seed", "1"};
  EXPECT_EQ(FindConfigPath(5, a), "a.toml");
  EXPECT_EQ(FindConfigPath(2, b), "b.toml");
  EXPECT_FALSE(FindConfigPath(3, none).has_value());
}

}  // namespace
}  // namespace brdf::sim

namespace brdf::sim {
namespace {

// --meter and [meter] model pick the meter on the pty (issue 41); a fault's code is the meter's
// own, so a PR-670's negative result codes are valid for it and for it only.
TEST(SimConfigMeter, FlagAndFileChooseTheMeterAndItsCodes) {
  SimConfig flags;
  ASSERT_TRUE(ParseLikeMain({"--meter", "pr670", "--serial-quality-code", "-8",
                             "--serial-leave-remote", "--meter-serial", "6700042"},
                            flags)
                  .ok());
  EXPECT_EQ(flags.meter, "pr670");
  EXPECT_EQ(flags.meter_serial, "6700042");
  EXPECT_EQ(flags.serial_faults.quality_code, -8);
  EXPECT_EQ(flags.serial_faults.quality_count, 1);
  EXPECT_TRUE(flags.serial_faults.leave_remote);
  EXPECT_EQ(MeterFamilyOf("pr655"), "pr670");
  EXPECT_EQ(MeterFamilyOf("cs3000"), "cs2000");
  EXPECT_EQ(MeterModelOf("cs2000a"), "CS-2000A");

  SimConfig pr650;
  EXPECT_FALSE(ParseLikeMain({"--serial-quality-code", "-8"}, pr650).ok());
  SimConfig unknown;
  EXPECT_FALSE(ParseLikeMain({"--meter", "pr999"}, unknown).ok());

  SimConfig file;
  ASSERT_TRUE(LoadConfigString("[meter]\nmodel = \"cs2000\"\nserial_number = \"2000777\"\n"
                               "[faults.serial]\nleave_remote = true\n",
                               "meter.toml", file)
                  .ok());
  EXPECT_EQ(file.meter, "cs2000");
  EXPECT_EQ(file.meter_serial, "2000777");
  EXPECT_TRUE(file.serial_faults.leave_remote);
  SimConfig bad;
  Status refused = LoadConfigString("[meter]\nmodel = \"cs-2000\"\n", "bad.toml", bad);
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("meter.model"), std::string::npos) << refused.message();
}

TEST(SimConfigTest, MaterialFromAFlagOrRelativeToTheConfigFile) {
  SimConfig flag;
  ASSERT_TRUE(ParseLikeMain({"--material", "/x/gold.toml"}, flag).ok());
  EXPECT_EQ(flag.optics.material_path, "/x/gold.toml");

  testing::TempDir dir;
  const std::string path = dir.file("sim.toml").string();
  std::ofstream(path) << "material = \"materials/gold.toml\"\n";
  SimConfig file;
  ASSERT_TRUE(ParseLikeMain({"--config", path}, file).ok());
  EXPECT_EQ(file.optics.material_path, (dir.path() / "materials/gold.toml").string());
  // A flag still wins, taken as given.
  SimConfig both;
  ASSERT_TRUE(ParseLikeMain({"--config", path, "--material", "here.toml"}, both).ok());
  EXPECT_EQ(both.optics.material_path, "here.toml");
}

TEST(SimConfigTest, AMaterialAndABuiltInSampleAreTwoSamples) {
  SimConfig c;
  const Status s = ParseLikeMain({"--material", "gold.toml", "--glossy"}, c);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("--material and --anisotropic/--glossy"), std::string::npos)
      << s.message();
}

TEST(SimConfigTest, ErrorSourcesFromTheFileAndFlags) {
  SimConfig c;
  ASSERT_TRUE(LoadConfigString(R"(
[optics.errors]
gain_noise = 0.001
lamp_drift_per_hour = -0.002
lamp_wander_per_sqrt_hour = 0.003
white_error = 0.01
pose_jitter_deg = 0.05
wavelength_shift_nm = 0.5
wavelength_shift_sigma_nm = 1.0
stray_light = 0.0004
[optics.detector]
read_noise_counts = 35
)",
                               "t.toml", c)
                  .ok());
  const ErrorSources& e = c.optics.errors;
  EXPECT_EQ(e.gain_noise, 0.001);
  EXPECT_EQ(e.lamp_drift_per_hour, -0.002);
  EXPECT_EQ(e.lamp_wander_per_sqrt_hour, 0.003);
  EXPECT_EQ(e.white_error, 0.01);
  EXPECT_EQ(e.pose_jitter_deg, 0.05);
  EXPECT_EQ(e.wavelength_shift_nm, 0.5);
  EXPECT_EQ(e.wavelength_shift_sigma_nm, 1.0);
  EXPECT_EQ(e.stray_light, 0.0004);
  EXPECT_EQ(c.optics.detector.read_noise_counts, 35);

  SimConfig f;
  ASSERT_TRUE(ParseLikeMain({"--gain-noise", "0.002", "--lamp-drift", "0.01", "--lamp-wander",
                             "0.02", "--white-error", "0.005", "--pose-jitter", "0.1",
                             "--wavelength-shift", "-1", "--wavelength-shift-sigma", "0.7",
                             "--stray-light", "0.001", "--read-noise", "40"},
                            f)
                  .ok());
  EXPECT_EQ(f.optics.errors.gain_noise, 0.002);
  EXPECT_EQ(f.optics.errors.lamp_drift_per_hour, 0.01);
  EXPECT_EQ(f.optics.errors.lamp_wander_per_sqrt_hour, 0.02);
  EXPECT_EQ(f.optics.errors.white_error, 0.005);
  EXPECT_EQ(f.optics.errors.pose_jitter_deg, 0.1);
  EXPECT_EQ(f.optics.errors.wavelength_shift_nm, -1);
  EXPECT_EQ(f.optics.errors.wavelength_shift_sigma_nm, 0.7);
  EXPECT_EQ(f.optics.errors.stray_light, 0.001);
  EXPECT_EQ(f.optics.detector.read_noise_counts, 40);
}

TEST(SimConfigTest, ErrorSourcesOutOfRangeAreNamed) {
  SimConfig c;
  const Status file =
      LoadConfigString("[optics.errors]\nwhite_error = 0.5\nstray = 0.1\n", "t.toml", c);
  EXPECT_NE(file.message().find("line 2, column 15: optics.errors.white_error: 0.5 is outside"),
            std::string::npos)
      << file.message();
  EXPECT_NE(file.message().find("unknown key optics.errors.stray"), std::string::npos)
      << file.message();
  const Status flag = ParseLikeMain({"--pose-jitter", "-1"}, c);
  EXPECT_EQ(flag.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(flag.message().find("--pose-jitter"), std::string::npos) << flag.message();
}

}  // namespace
}  // namespace brdf::sim
