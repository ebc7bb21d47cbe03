// brdfd's TOML configuration: defaults, every key, and every way a file can be refused.
#include "daemon/config/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <tuple>

#include "drivers/stage/modbus_stage.h"
#include "tests/support/test_env.h"

namespace brdf::daemon {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

// Parses text that must be refused; returns the message.
std::string Refusal(const std::string& toml) {
  const Result<Config> r = ParseConfig(toml, "test.toml");
  EXPECT_FALSE(r.ok()) << "accepted:\n" << toml;
  if (r.ok()) return "";
  EXPECT_EQ(r.status().code(), StatusCode::kConfigurationError);
  return r.status().message();
}

TEST(ConfigTest, EmptyFileGivesTheDefaults) {
  const Result<Config> r = ParseConfig("", "empty.toml");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const Config& c = *r;
  EXPECT_EQ(c.server.listen, "127.0.0.1:50051");
  EXPECT_FALSE(c.server.tls.has_value());
  EXPECT_FALSE(c.storage.database.empty());
  EXPECT_EQ(c.meter.baud, 9600);
  EXPECT_EQ(c.meter.pacing_ms, 100);
  EXPECT_TRUE(c.meter.measure_with_spectrum);
  EXPECT_TRUE(c.meter.quality_overrides.empty());
  EXPECT_EQ(c.stage.transport, "tcp");
  EXPECT_EQ(c.stage.profile, "az");
  EXPECT_TRUE(c.stage.alpha.present);
  EXPECT_TRUE(c.stage.beta.present);
  EXPECT_FALSE(c.stage.gamma.present);
  EXPECT_FALSE(c.stage.delta.present);
  EXPECT_FALSE(c.stage.detector_arm_motorized);
  EXPECT_DOUBLE_EQ(c.sample.white_reflectance, 0.99);
  EXPECT_TRUE(c.tokens.empty());
  EXPECT_EQ(c.log.level, "info");
  // The estimate's meter times: 0.3 s overhead, adaptive 2 s reference and sample, 6 s dark.
  const plan::RigDescription rig = ToRigDescription(c);
  EXPECT_NEAR(rig.reading_overhead_s, 0.3, 1e-12);
  EXPECT_NEAR(rig.adaptive_integration.reference_s, 2.0, 1e-12);
  EXPECT_NEAR(rig.adaptive_integration.dark_s, 6.0, 1e-12);
  EXPECT_NEAR(rig.adaptive_integration.sample_s, 2.0, 1e-12);
}

// [index] bounds the interpolation index cache: sessions kept and their memory, MB.
TEST(ConfigTest, IndexCacheBounds) {
  const Result<Config> none = ParseConfig("", "empty.toml");
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->index.max_sessions, 8);
  EXPECT_EQ(none->index.max_mb, 512);
  const Result<Config> r = ParseConfig("[index]\nmax_sessions = 2\nmax_mb = 64\n", "lab.toml");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->index.max_sessions, 2);
  EXPECT_EQ(r->index.max_mb, 64);
  EXPECT_THAT(Refusal("[index]\nmax_sessions = 0\n"), HasSubstr("index.max_sessions"));
  EXPECT_THAT(Refusal("[index]\nmax_mb = 8\n"), HasSubstr("index.max_mb"));
  EXPECT_THAT(Refusal("[index]\nmax_entries = 3\n"), HasSubstr("index.max_entries"));
}

// [export] bounds the exports' kept interpolants: entries and their estimated memory, MB (0: half
// of [server] memory_budget_mb).
TEST(ConfigTest, ExportCacheBounds) {
  const Result<Config> none = ParseConfig("", "empty.toml");
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->exports.max_entries, 4);
  EXPECT_EQ(none->exports.max_mb, 0);
  const Result<Config> r = ParseConfig("[export]\nmax_entries = 1\nmax_mb = 128\n", "lab.toml");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->exports.max_entries, 1);
  EXPECT_EQ(r->exports.max_mb, 128);
  EXPECT_THAT(Refusal("[export]\nmax_entries = 0\n"), HasSubstr("export.max_entries"));
  EXPECT_THAT(Refusal("[export]\nmax_entries = 0\n"), HasSubstr("0 is outside 1"));
  EXPECT_THAT(Refusal("[export]\nmax_entries = 2000\n"), HasSubstr("export.max_entries"));
  EXPECT_THAT(Refusal("[export]\nmax_mb = -1\n"), HasSubstr("export.max_mb"));
  EXPECT_THAT(Refusal("[export]\nmax_sessions = 3\n"), HasSubstr("export.max_sessions"));
  EXPECT_THAT(Refusal("[export]\nmax_entries = \"one\"\n"), HasSubstr("export.max_entries"));
}

// [rig] names the sessions (default: the host name); [archive] ships them to the lab's PostgreSQL
// and needs a credentials file, never a conninfo in the configuration itself.
TEST(ConfigTest, RigNameAndArchive) {
  const Result<Config> none = ParseConfig("", "empty.toml");
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->archive.enabled());
  EXPECT_FALSE(RigName(*none).empty());
  const Result<Config> r = ParseConfig(
      "[rig]\nname = \"rig-a\"\n[archive]\ncredentials = \"/etc/brdfd/archive.conninfo\"\n"
      "batch_readings = 50\nretry_ms = 500\n",
      "lab.toml");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(RigName(*r), "rig-a");
  EXPECT_TRUE(r->archive.enabled());
  EXPECT_EQ(r->archive.credentials, "/etc/brdfd/archive.conninfo");
  EXPECT_EQ(r->archive.batch_readings, 50);
  EXPECT_EQ(r->archive.retry_ms, 500);
  EXPECT_THAT(Refusal("[archive]\nretry_ms = 500\n"), HasSubstr("archive.credentials: missing"));
  EXPECT_THAT(Refusal("[archive]\ncredentials = \"f\"\nconninfo = \"host=x password=y\"\n"),
              HasSubstr("archive.conninfo"));
  EXPECT_THAT(Refusal("[archive]\ncredentials = \"f\"\nbatch_readings = 0\n"),
              HasSubstr("archive.batch_readings"));
}

// [rig] time_scale: a simulated rig's speed-up (brdf-sim --time-scale) reaches the timing model,
// so that estimates and ETAs are the simulator's; 1 (a real rig) by default; > 0.
TEST(ConfigTest, RigTimeScaleReachesTheTimingModel) {
  const Result<Config> none = ParseConfig("", "empty.toml");
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->rig.time_scale, 1);
  EXPECT_EQ(ToRigDescription(*none).time_scale, 1);
  const Result<Config> sim = ParseConfig("[rig]\ntime_scale = 8\n", "sim.toml");
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  EXPECT_EQ(sim->rig.time_scale, 8);
  EXPECT_EQ(ToRigDescription(*sim).time_scale, 8);
  for (const char* bad : {"0", "-2", "10001", "\"fast\""}) {
    EXPECT_THAT(Refusal(std::string("[rig]\ntime_scale = ") + bad + "\n"),
                HasSubstr("rig.time_scale"))
        << bad;
  }
}

TEST(ConfigTest, FullFile) {
  const Result<Config> r = ParseConfig(R"(
[server]
listen = "0.0.0.0:6000"
[server.tls]
cert = "/etc/brdfd/server.crt"
key = "/etc/brdfd/server.key"
client_ca = "/etc/brdfd/ca.crt"

[storage]
database = "/tmp/brdfd.db"

[meter]
port = "/dev/ttyS3"
baud = 19200
hardware_flow_control = true
pacing_ms = 50
quiet_gap_ms = 20
reply_timeout_ms = 1500
measurement_timeout_ms = 20000
wake_attempts = 3
measure_with_spectrum = false
rts_settle_ms = 700
overhead_ms = 1000
adaptive_reference_ms = 150
adaptive_dark_ms = 6000
adaptive_sample_ms = 650
[meter.quality]
18 = "fail"
"30" = { action = "retry", accept_flagged_when_exhausted = true }

[stage]
transport = "rtu"
device = "/dev/ttyUSB1"
baud = 57600
parity = "N"
profile = "leadshine"
response_timeout_ms = 800
detector_arm_motorized = true
[stage.axes.alpha]
unit_id = 5
counts_per_degree = 100
zero_offset_deg = 2.5
sign = -1
min_deg = -10
max_deg = 80
speed_deg_s = 15
[stage.axes.gamma]
present = true
unit_id = 7
[stage.axes.delta]
unit_id = 8

[sample]
white_reflectance = 0.985

[[auth.tokens]]
name = "lab-pc"
token = "0123456789abcdef0123"
role = "operator"
[[auth.tokens]]
name = "notebook"
token = "fedcba9876543210fedc"
role = "analyst"

[log]
level = "debug"
)",
                                       "full.toml");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const Config& c = *r;
  EXPECT_EQ(c.server.listen, "0.0.0.0:6000");
  ASSERT_TRUE(c.server.tls.has_value());
  EXPECT_EQ(c.server.tls->client_ca, "/etc/brdfd/ca.crt");
  EXPECT_EQ(c.storage.database, "/tmp/brdfd.db");
  EXPECT_EQ(c.meter.port, "/dev/ttyS3");
  EXPECT_EQ(c.meter.baud, 19200);
  EXPECT_TRUE(c.meter.hardware_flow_control);
  EXPECT_EQ(c.meter.measurement_timeout_ms, 20000);
  EXPECT_FALSE(c.meter.measure_with_spectrum);
  EXPECT_EQ(c.meter.rts_settle_ms, 700);
  ASSERT_EQ(c.meter.quality_overrides.size(), 2u);
  EXPECT_EQ(c.meter.quality_overrides.at(18).action, drivers::pr650::QualityAction::kFail);
  EXPECT_EQ(c.meter.quality_overrides.at(30).action, drivers::pr650::QualityAction::kRetry);
  EXPECT_TRUE(c.meter.quality_overrides.at(30).accept_flagged_when_exhausted);
  EXPECT_EQ(c.stage.transport, "rtu");
  EXPECT_EQ(c.stage.device, "/dev/ttyUSB1");
  EXPECT_EQ(c.stage.parity, 'N');
  EXPECT_EQ(c.stage.profile, "leadshine");
  EXPECT_EQ(c.stage.alpha.unit_id, 5);
  EXPECT_EQ(c.stage.alpha.sign, -1);
  EXPECT_EQ(c.stage.alpha.max_deg, 80);
  EXPECT_TRUE(c.stage.gamma.present);
  EXPECT_TRUE(c.stage.delta.present);  // follows detector_arm_motorized
  EXPECT_DOUBLE_EQ(c.sample.white_reflectance, 0.985);
  ASSERT_EQ(c.tokens.size(), 2u);
  EXPECT_EQ(c.tokens[0].role, Role::kOperator);
  EXPECT_EQ(c.tokens[1].role, Role::kAnalyst);
  EXPECT_EQ(c.log.level, "debug");

  const plan::RigDescription rig = ToRigDescription(c);
  EXPECT_TRUE(rig.has_gamma_axis);
  EXPECT_TRUE(rig.has_detector_arm);
  EXPECT_EQ(rig.alpha.max_deg, 80);
  EXPECT_EQ(rig.alpha.speed_deg_s, 15);
  EXPECT_EQ(rig.convention.alpha.sign, -1);
  EXPECT_EQ(rig.convention.alpha.zero_deg, 2.5);
  // 19200 baud moves the D5 report twice as fast as 9600.
  Config slow = c;
  slow.meter.baud = 9600;
  EXPECT_NEAR(ToRigDescription(slow).meter_transfer_s, 2 * rig.meter_transfer_s, 1e-12);
  EXPECT_NEAR(ToRigDescription(slow).meter_transfer_s, 1.8, 0.05);  // pr650.md: ~1.8 s
  // The estimate's host time per reading: pacing and quiet gap per exchange, two exchanges with
  // M0 then D5 (this file sets measure_with_spectrum = false), one with M5; the part after the
  // measurement (which a pipelined move overlaps) is D5's exchange, or M5's quiet gap.
  const double exchange = (c.meter.pacing_ms + c.meter.quiet_gap_ms) / 1000.0;
  // The meter's overhead and adaptive integration by kind, as set above.
  EXPECT_NEAR(rig.reading_overhead_s, 1.0, 1e-12);
  EXPECT_NEAR(rig.adaptive_integration.reference_s, 0.150, 1e-12);
  EXPECT_NEAR(rig.adaptive_integration.dark_s, 6.0, 1e-12);
  EXPECT_NEAR(rig.adaptive_integration.sample_s, 0.650, 1e-12);
  EXPECT_NEAR(rig.reading_host_s, 2 * exchange, 1e-12);
  EXPECT_NEAR(rig.reading_host_after_s, exchange, 1e-12);
  Config m5 = c;
  m5.meter.measure_with_spectrum = true;
  EXPECT_NEAR(ToRigDescription(m5).reading_host_s, exchange, 1e-12);
  EXPECT_NEAR(ToRigDescription(m5).reading_host_after_s, c.meter.quiet_gap_ms / 1000.0, 1e-12);
  // The stage is polled at the driver's interval, which the configuration does not change.
  EXPECT_NEAR(
      rig.stage_poll_s,
      std::chrono::duration<double>(drivers::stage::ModbusStageConfig{}.poll_interval).count(),
      1e-12);
}

TEST(ConfigTest, StreamCapsAndStallTimeout) {
  Result<Config> r = ParseConfig(
      "[server]\nmax_streams_per_token = 8\nmax_streams_analyst = 100\n"
      "max_streams_operator = 20\nmax_streams_unauthenticated = 0\nstream_stall_timeout_s = 5\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->server.max_streams_per_token, 8);
  EXPECT_EQ(r->server.max_streams_analyst, 100);
  EXPECT_EQ(r->server.max_streams_operator, 20);
  EXPECT_EQ(r->server.max_streams_unauthenticated, 0);  // no health Watch, no reflection
  EXPECT_EQ(r->server.stream_stall_timeout_s, 5);
  Result<Config> defaults = ParseConfig("");
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->server.max_streams_per_token, 64);
  EXPECT_EQ(defaults->server.max_streams_analyst, 1024);
  EXPECT_EQ(defaults->server.max_streams_operator, 256);
  EXPECT_EQ(defaults->server.max_streams_unauthenticated, 64);
  EXPECT_EQ(defaults->server.stream_stall_timeout_s, 60);
  EXPECT_THAT(Refusal("[server]\nmax_streams_per_token = 0\n"),
              HasSubstr("server.max_streams_per_token"));
  EXPECT_THAT(Refusal("[server]\nmax_streams_operator = 0\n"),
              HasSubstr("server.max_streams_operator"));
  EXPECT_THAT(Refusal("[server]\nstream_stall_timeout_s = 0\n"),
              HasSubstr("server.stream_stall_timeout_s"));
}

TEST(ConfigTest, MemoryBudget) {
  Result<Config> r = ParseConfig("[server]\nmemory_budget_mb = 512\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->server.memory_budget_mb, 512);
  Result<Config> defaults = ParseConfig("");
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->server.memory_budget_mb, 2048);
  EXPECT_THAT(Refusal("[server]\nmemory_budget_mb = 15\n"), HasSubstr("server.memory_budget_mb"));
}

TEST(ConfigTest, InterpolateLoopThreadsAndCpus) {
  Result<Config> r = ParseConfig("[server]\ninterpolate_threads = 2\ninterpolate_cpus = [1, 0]\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->server.interpolate_threads, 2);
  EXPECT_EQ(r->server.interpolate_cpus, (std::vector<int>{1, 0}));
  Result<Config> defaults = ParseConfig("");
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->server.interpolate_threads, 0);  // one per two cores
  EXPECT_TRUE(defaults->server.interpolate_cpus.empty());

  EXPECT_THAT(Refusal("[server]\ninterpolate_threads = 0\n"),
              HasSubstr("server.interpolate_threads"));
  EXPECT_THAT(Refusal("[server]\ninterpolate_cpus = []\n"),
              HasSubstr("server.interpolate_cpus: must be a non-empty array of CPU numbers"));
  EXPECT_THAT(Refusal("[server]\ninterpolate_cpus = 1\n"),
              HasSubstr("server.interpolate_cpus: must be a non-empty array"));
  EXPECT_THAT(Refusal("[server]\ninterpolate_cpus = [0, -1]\n"),
              HasSubstr("server.interpolate_cpus: holds -1; give CPU numbers 0 … 1023"));
  EXPECT_THAT(Refusal("[server]\ninterpolate_cpus = [\"1\"]\n"), HasSubstr("a non-integer"));
  EXPECT_THAT(Refusal("[server]\ninterpolate_cpus = [4096]\n"), HasSubstr("holds 4096"));
}

TEST(ConfigTest, UnknownKeysAreRefusedByFullPath) {
  const std::string m = Refusal("[stage.axes.alpa]\nunit_id = 1\n");
  EXPECT_THAT(m, HasSubstr("unknown key stage.axes.alpa"));
  EXPECT_THAT(m, HasSubstr("line 1"));
  EXPECT_THAT(m, HasSubstr("test.toml"));
  EXPECT_THAT(Refusal("[server]\nlisten_on = \"x:1\"\n"),
              HasSubstr("unknown key server.listen_on"));
  EXPECT_THAT(Refusal("verbose = true\n"), HasSubstr("unknown key verbose"));
  EXPECT_THAT(Refusal("[stage.axes.beta]\nspeed = 3\n"),
              HasSubstr("unknown key stage.axes.beta.speed"));
  EXPECT_THAT(Refusal("[meter.quality]\n30 = { action = \"retry\", flag = true }\n"),
              HasSubstr("unknown key meter.quality.30.flag"));
  EXPECT_THAT(Refusal("[[auth.tokens]]\nname = \"a\"\ntoken = \"0123456789abcdef\"\n"
                      "role = \"operator\"\nexpires = 3\n"),
              HasSubstr("unknown key auth.tokens[0].expires"));
}

TEST(ConfigTest, SyntaxErrorsAreStatusesNotExceptions) {
  const std::string m = Refusal("[server\nlisten = 1\n");
  EXPECT_THAT(m, HasSubstr("not valid TOML"));
  EXPECT_THAT(m, HasSubstr("line 1"));
  EXPECT_THAT(Refusal("a = \"unterminated\n"), HasSubstr("not valid TOML"));
  EXPECT_THAT(Refusal("[log]\nlevel = \"info\"\n[log]\nlevel = \"debug\"\n"),
              HasSubstr("not valid TOML"));  // table defined twice
}

TEST(ConfigTest, UncertaintyTermsWithTheirDefaultsAndRanges) {
  const Result<Config> defaults = ParseConfig("", "empty.toml");
  ASSERT_TRUE(defaults.ok());
  EXPECT_NEAR(defaults->sample.white_reflectance_uncertainty, 0.01 / std::sqrt(3.0), 1e-15);
  EXPECT_TRUE(defaults->uncertainty.enabled);
  EXPECT_NEAR(defaults->uncertainty.wavelength_nm, 2 / std::sqrt(3.0), 1e-15);
  EXPECT_FALSE(defaults->uncertainty.lamp_drift_per_hour.has_value());
  EXPECT_DOUBLE_EQ(defaults->uncertainty.meter_full_well_counts, 2e5);

  const Result<Config> set = ParseConfig(R"([sample]
white_reflectance_uncertainty = 0.005
[uncertainty]
enabled = false
wavelength_nm = 1.0
stray_light = 0.0002
stage_repeatability_deg = 0.02
stage_alignment_deg = 0.01
lamp_drift_per_hour = -0.002
meter_full_scale = 0.05
meter_full_well_counts = 1e5
meter_read_noise_counts = 10
meter_adaptive_fill = 0.6
meter_gain_repeatability = 0.001
)",
                                         "u.toml");
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_DOUBLE_EQ(set->sample.white_reflectance_uncertainty, 0.005);
  const UncertaintyConfig& u = set->uncertainty;
  EXPECT_FALSE(u.enabled);
  EXPECT_DOUBLE_EQ(u.wavelength_nm, 1.0);
  EXPECT_DOUBLE_EQ(u.stray_light, 0.0002);
  EXPECT_DOUBLE_EQ(u.stage_repeatability_deg, 0.02);
  EXPECT_DOUBLE_EQ(u.stage_alignment_deg, 0.01);
  EXPECT_EQ(u.lamp_drift_per_hour, -0.002);
  EXPECT_DOUBLE_EQ(u.meter_full_scale, 0.05);
  EXPECT_DOUBLE_EQ(u.meter_full_well_counts, 1e5);
  EXPECT_DOUBLE_EQ(u.meter_read_noise_counts, 10);
  EXPECT_DOUBLE_EQ(u.meter_adaptive_fill, 0.6);
  EXPECT_DOUBLE_EQ(u.meter_gain_repeatability, 0.001);

  EXPECT_THAT(Refusal("[sample]\nwhite_reflectance_uncertainty = 0.6\n"),
              HasSubstr("sample.white_reflectance_uncertainty"));
  EXPECT_THAT(Refusal("[uncertainty]\nwavelength_nm = -1\n"),
              HasSubstr("uncertainty.wavelength_nm"));
  EXPECT_THAT(Refusal("[uncertainty]\nmeter_full_scale = 0\n"),
              HasSubstr("uncertainty.meter_full_scale"));
  EXPECT_THAT(Refusal("[uncertainty]\nstray = 0.1\n"), HasSubstr("unknown key uncertainty.stray"));
  EXPECT_THAT(Refusal("[uncertainty]\nenabled = 1\n"), HasSubstr("must be true or false"));
}

TEST(ConfigTest, WrongTypes) {
  EXPECT_THAT(Refusal("[meter]\nbaud = \"9600\"\n"), HasSubstr("meter.baud: must be an integer"));
  EXPECT_THAT(Refusal("[stage]\ndetector_arm_motorized = 1\n"),
              HasSubstr("stage.detector_arm_motorized: must be true or false"));
  EXPECT_THAT(Refusal("server = 3\n"), HasSubstr("server: must be a table"));
  EXPECT_THAT(Refusal("[sample]\nwhite_reflectance = \"high\"\n"), HasSubstr("must be a number"));
  EXPECT_THAT(Refusal("[auth]\ntokens = 5\n"), HasSubstr("auth.tokens: must be an array"));
  EXPECT_THAT(Refusal("[meter.quality]\n18 = 3\n"), HasSubstr("meter.quality.18"));
}

TEST(ConfigTest, ValuesOutOfRange) {
  EXPECT_THAT(Refusal("[server]\nlisten = \"localhost\"\n"), HasSubstr("server.listen"));
  EXPECT_THAT(Refusal("[server]\nlisten = \"localhost:70000\"\n"), HasSubstr("port 70000"));
  EXPECT_THAT(Refusal("[server]\nlisten = \"unix:\"\n"), HasSubstr("socket path"));
  EXPECT_THAT(Refusal("[storage]\ndatabase = \"\"\n"),
              HasSubstr("storage.database: must not be empty"));
  EXPECT_THAT(Refusal("[meter]\nbaud = 9601\n"), HasSubstr("not a standard rate"));
  EXPECT_THAT(Refusal("[meter]\npacing_ms = -1\n"), HasSubstr("meter.pacing_ms: -1 is outside"));
  EXPECT_THAT(Refusal("[meter]\nmeasurement_timeout_ms = 10\n"),
              HasSubstr("meter.measurement_timeout_ms"));
  EXPECT_THAT(Refusal("[meter]\nrts_settle_ms = 20000\n"), HasSubstr("meter.rts_settle_ms"));
  EXPECT_THAT(Refusal("[meter]\noverhead_ms = -5\n"),
              HasSubstr("meter.overhead_ms: -5 is outside 0 … 60000"));
  EXPECT_THAT(Refusal("[meter]\nadaptive_dark_ms = 9000\n"),
              HasSubstr("meter.adaptive_dark_ms: 9000 is outside 10 … 6000"));
  EXPECT_THAT(Refusal("[meter]\nadaptive_reference_ms = 0\n"),
              HasSubstr("meter.adaptive_reference_ms: 0 is outside 10 … 6000"));
  EXPECT_THAT(Refusal("[meter]\nadaptive_sample_ms = \"650\"\n"),
              HasSubstr("meter.adaptive_sample_ms: must be an integer"));
  // The old single time is not a key: a misspelt or merged key is refused, naming the known ones.
  EXPECT_THAT(
      Refusal("[meter]\nadaptive_integration_ms = 2000\n"),
      AllOf(HasSubstr("unknown key meter.adaptive_integration_ms"), HasSubstr("adaptive_dark_ms")));
  EXPECT_THAT(Refusal("[meter.quality]\n123 = \"retry\"\n"), HasSubstr("not a quality code"));
  EXPECT_THAT(Refusal("[meter.quality]\n18 = \"ignore\"\n"), HasSubstr("\"ignore\" is not one of"));
  EXPECT_THAT(Refusal("[meter.quality]\n18 = {}\n"), HasSubstr("meter.quality.18.action: missing"));
  EXPECT_THAT(Refusal("[stage]\ntransport = \"udp\"\n"), HasSubstr("stage.transport"));
  EXPECT_THAT(Refusal("[stage]\ntransport = \"rtu\"\n"), HasSubstr("stage.device: missing"));
  EXPECT_THAT(Refusal("[stage]\naddress = \"10.0.0.1\"\n"), HasSubstr("stage.address"));
  EXPECT_THAT(Refusal("[stage]\naddress = \"10.0.0.1:0\"\n"), HasSubstr("port 0"));
  EXPECT_THAT(Refusal("[stage]\nparity = \"X\"\n"), HasSubstr("stage.parity"));
  EXPECT_THAT(Refusal("[stage]\nprofile = \"arcus\"\n"), HasSubstr("stage.profile"));
  EXPECT_THAT(Refusal("[stage]\nprofile = \"az\"\nprofile_file = \"/etc/brdfd/s.toml\"\n"),
              HasSubstr("stage.profile_file: given with profile; keep one"));
  EXPECT_THAT(Refusal("[stage]\nprofile_file = \"\"\n"),
              HasSubstr("stage.profile_file: must not be empty"));
  EXPECT_THAT(Refusal("[stage.axes.alpha]\nunit_id = 0\n"), HasSubstr("stage.axes.alpha.unit_id"));
  EXPECT_THAT(Refusal("[stage.axes.alpha]\ncounts_per_degree = 0\n"),
              HasSubstr("stage.axes.alpha.counts_per_degree"));
  EXPECT_THAT(Refusal("[stage.axes.alpha]\nspeed_deg_s = -5\n"),
              HasSubstr("stage.axes.alpha.speed_deg_s"));
  EXPECT_THAT(Refusal("[stage.axes.alpha]\nsign = 0.5\n"), HasSubstr("must be 1 or -1"));
  EXPECT_THAT(Refusal("[stage.axes.beta]\nmin_deg = 10\nmax_deg = 5\n"),
              HasSubstr("stage.axes.beta.max_deg"));
  EXPECT_THAT(Refusal("[stage.axes.beta]\nmax_deg = nan\n"), HasSubstr("finite"));
  EXPECT_THAT(Refusal("[stage.axes.alpha]\npresent = false\n"),
              HasSubstr("stage.axes.alpha.present"));
  EXPECT_THAT(Refusal("[stage.axes.gamma]\npresent = true\nunit_id = 1\n"),
              HasSubstr("stage.axes.gamma.unit_id: 1 is also the unit id of alpha"));
  EXPECT_THAT(
      Refusal("[stage]\ndetector_arm_motorized = true\n[stage.axes.delta]\npresent = false\n"),
      HasSubstr("contradicts"));
  EXPECT_THAT(Refusal("[stage.axes.delta]\npresent = true\n"), HasSubstr("contradicts"));
  EXPECT_THAT(Refusal("[sample]\nwhite_reflectance = 0\n"), HasSubstr("sample.white_reflectance"));
  EXPECT_THAT(Refusal("[sample]\nwhite_reflectance = 1.2\n"),
              HasSubstr("sample.white_reflectance"));
  EXPECT_THAT(Refusal("[log]\nlevel = \"verbose\"\n"), HasSubstr("log.level"));
}

TEST(ConfigTest, TlsNeedsCertAndKey) {
  EXPECT_THAT(Refusal("[server.tls]\ncert = \"a.crt\"\n"), HasSubstr("server.tls.key: missing"));
  EXPECT_THAT(Refusal("[server.tls]\nkey = \"a.key\"\n"), HasSubstr("server.tls.cert: missing"));
  EXPECT_THAT(Refusal("[server.tls]\nclient_ca = \"ca.crt\"\n"), HasSubstr("neither cert nor key"));
}

TEST(ConfigTest, TokenProblems) {
  const std::string base =
      "[[auth.tokens]]\nname = \"a\"\ntoken = \"0123456789abcdef\"\nrole = \"operator\"\n";
  ASSERT_TRUE(ParseConfig(base).ok());
  EXPECT_THAT(Refusal("[[auth.tokens]]\nname = \"a\"\ntoken = \"short\"\nrole = \"operator\"\n"),
              HasSubstr("auth.tokens[0].token: is 5 characters"));
  EXPECT_THAT(Refusal("[[auth.tokens]]\ntoken = \"0123456789abcdef\"\nrole = \"operator\"\n"),
              HasSubstr("auth.tokens[0].name: missing"));
  EXPECT_THAT(Refusal("[[auth.tokens]]\nname = \"a\"\nrole = \"operator\"\n"),
              HasSubstr("auth.tokens[0].token: missing"));
  EXPECT_THAT(Refusal("[[auth.tokens]]\nname = \"a\"\ntoken = \"0123456789abcdef\"\n"),
              HasSubstr("auth.tokens[0].role: missing"));
  EXPECT_THAT(
      Refusal("[[auth.tokens]]\nname = \"a\"\ntoken = \"0123456789abcdef\"\nrole = \"admin\"\n"),
      HasSubstr("auth.tokens[0].role"));
  EXPECT_THAT(
      Refusal(base +
              "[[auth.tokens]]\nname = \"a\"\ntoken = \"0123456789abcdeX\"\nrole = \"analyst\"\n"),
      HasSubstr("auth.tokens[1].name: \"a\" is used by another token"));
  const std::string same_secret = Refusal(
      base + "[[auth.tokens]]\nname = \"b\"\ntoken = \"0123456789abcdef\"\nrole = \"analyst\"\n");
  EXPECT_THAT(same_secret, HasSubstr("auth.tokens[1].token: is the same secret"));
  EXPECT_THAT(same_secret, Not(HasSubstr("0123456789abcdef")));  // secrets are never echoed
}

TEST(ConfigTest, EveryProblemIsReportedAtOnce) {
  const std::string m =
      Refusal("[meter]\nbaud = 1\n[stage]\nprofile = \"x\"\n[log]\nlevel = \"loud\"\n[bogus]\n");
  EXPECT_THAT(m, HasSubstr("meter.baud"));
  EXPECT_THAT(m, HasSubstr("stage.profile"));
  EXPECT_THAT(m, HasSubstr("log.level"));
  EXPECT_THAT(m, HasSubstr("unknown key bogus"));
}

TEST(ConfigTest, LoadConfigReadsFilesAndReportsMissingOnes) {
  brdf::testing::TempDir dir("brdf-config-test");
  ASSERT_FALSE(dir.path().empty()) << dir.error();
  const std::string path = dir.file("brdfd.toml").string();
  {
    std::ofstream out(path);
    out << "[server]\nlisten = \"127.0.0.1:0\"\n[stage]\nadress = \"x:1\"\n";
  }
  const Result<Config> bad = LoadConfig(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.status().message(), HasSubstr(path));
  EXPECT_THAT(bad.status().message(), HasSubstr("line 4"));
  EXPECT_THAT(bad.status().message(), HasSubstr("unknown key stage.adress"));
  {
    std::ofstream out(path);
    out << "[server]\nlisten = \"127.0.0.1:0\"\n";
  }
  const Result<Config> good = LoadConfig(path);
  ASSERT_TRUE(good.ok()) << good.status().ToString();
  EXPECT_EQ(good->server.listen, "127.0.0.1:0");
  const Result<Config> missing = LoadConfig(dir.file("absent.toml").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

TEST(ConfigTest, OversizedFileIsRefused) {
  std::string big = "# " + std::string(kMaxConfigBytes, 'x') + "\n";
  EXPECT_THAT(Refusal(big), HasSubstr("cap"));
}

TEST(ConfigTest, WebConsoleIsOffUnlessListenIsSet) {
  Result<Config> defaults = ParseConfig("");
  ASSERT_TRUE(defaults.ok());
  EXPECT_TRUE(defaults->web.listen.empty());
  EXPECT_TRUE(defaults->web.root.empty());
  Result<Config> r = ParseConfig("[web]\nlisten = \"127.0.0.1:0\"\nroot = \"/srv/brdfd-web\"\n");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->web.listen, "127.0.0.1:0");
  EXPECT_EQ(r->web.root, "/srv/brdfd-web");
  EXPECT_THAT(Refusal("[web]\nlisten = \"8080\"\n"), HasSubstr("web.listen"));
  EXPECT_THAT(Refusal("[web]\nlisten = \"127.0.0.1:70000\"\n"), HasSubstr("web.listen"));
  EXPECT_THAT(Refusal("[web]\nlisen = \"127.0.0.1:8080\"\n"), HasSubstr("unknown key web.lisen"));
}

}  // namespace
}  // namespace brdf::daemon

namespace brdf::daemon {
namespace {

// [meter] model picks the driver (issue 41); the PR-650 stays the default, and its transfer time
// follows the meter's report size.
TEST(ConfigMeterModel, ModelPicksTheFamilyAndUnknownModelsAreRefused) {
  const Result<Config> defaults = ParseConfig("", "empty.toml");
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->meter.model, MeterModel::kPr650);
  EXPECT_EQ(defaults->meter.char_gap_ms, 50);
  EXPECT_EQ(defaults->meter.nd_filter, "auto");
  for (const auto& [key, family, name] : {std::tuple{"pr650", MeterFamily::kPr650, "PR-650"},
                                          std::tuple{"pr655", MeterFamily::kPr670, "PR-655"},
                                          std::tuple{"pr670", MeterFamily::kPr670, "PR-670"},
                                          std::tuple{"cs2000", MeterFamily::kCs2000, "CS-2000"},
                                          std::tuple{"cs2000a", MeterFamily::kCs2000, "CS-2000A"},
                                          std::tuple{"cs3000", MeterFamily::kCs2000, "CS-3000"}}) {
    const Result<Config> r = ParseConfig(
        std::string("[meter]\nmodel = \"") + key + "\"\nchar_gap_ms = 5\nnd_filter = \"off\"\n",
        "meter.toml");
    ASSERT_TRUE(r.ok()) << key << ": " << r.status().ToString();
    EXPECT_EQ(FamilyOf(r->meter.model), family) << key;
    EXPECT_STREQ(MeterModelName(r->meter.model), name);
    EXPECT_STREQ(MeterModelKey(r->meter.model), key);
    EXPECT_EQ(r->meter.char_gap_ms, 5);
    EXPECT_EQ(r->meter.nd_filter, "off");
  }
  const Result<Config> bad = ParseConfig("[meter]\nmodel = \"pr-670\"\n", "bad.toml");
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.status().message(), ::testing::HasSubstr("meter.model"));
  EXPECT_THAT(bad.status().message(), ::testing::HasSubstr("pr670"));
  const Result<Config> nd = ParseConfig("[meter]\nnd_filter = \"half\"\n", "bad.toml");
  EXPECT_FALSE(nd.ok());

  const Result<Config> pr650 = ParseConfig("", "a.toml");
  const Result<Config> cs = ParseConfig("[meter]\nmodel = \"cs2000\"\n", "b.toml");
  EXPECT_GT(ToRigDescription(*cs).meter_transfer_s, ToRigDescription(*pr650).meter_transfer_s);
}

}  // namespace
}  // namespace brdf::daemon
