// The simulator's PR-650 endpoint on its own, through a plain POSIX client on the pty: the exact
// bytes of each reply, setup checking, remote-mode entry, faults.
#include "tools/brdf-sim/meter/pr650_endpoint.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "core/wavelength_grid.h"
#include "drivers/pr650/protocol.h"
#include "tests/drivers_pr650/pr650_test_rig.h"
#include "tools/brdf-sim/meter/pr650_protocol.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;
using ::testing::StartsWith;
using SteadyClock = std::chrono::steady_clock;

// A raw serial client: writes bytes, reads until the line has been quiet for a while.
class RawClient {
 public:
  explicit RawClient(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd_ >= 0) {
      termios t{};
      ::tcgetattr(fd_, &t);
      ::cfmakeraw(&t);
      ::tcsetattr(fd_, TCSANOW, &t);
    }
  }
  ~RawClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }

  // Sends `bytes` and returns everything that arrives until `quiet` passes without a byte (or
  // `limit` overall). `hangup` is set when the port hung up; `reads` holds each read's size.
  std::string Ask(const std::string& bytes, std::chrono::milliseconds quiet = 80ms,
                  std::chrono::milliseconds limit = 5s) {
    if (::write(fd_, bytes.data(), bytes.size()) != static_cast<ssize_t>(bytes.size())) return {};
    std::string out;
    reads.clear();
    const auto end = SteadyClock::now() + limit;
    auto last = SteadyClock::now();
    while (SteadyClock::now() < end && SteadyClock::now() - last < quiet) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 5) <= 0) continue;
      char buffer[512];
      const ssize_t n = ::read(fd_, buffer, sizeof buffer);
      if (n > 0) {
        out.append(buffer, static_cast<std::size_t>(n));
        reads.push_back(static_cast<std::size_t>(n));
        last = SteadyClock::now();
      } else if (p.revents & (POLLHUP | POLLERR)) {
        hangup = true;
        break;
      }
    }
    return out;
  }

  bool hangup = false;
  std::vector<std::size_t> reads;

 private:
  int fd_ = -1;
};

class Pr650EndpointTest : public ::testing::Test {
 protected:
  void Start(sim::Pr650EndpointOptions options = FastEndpointOptions()) {
    endpoint_ = std::make_unique<sim::Pr650Endpoint>(backend_, control_, options);
    ASSERT_TRUE(endpoint_->Start().ok());
    client_ = std::make_unique<RawClient>(endpoint_->path());
    ASSERT_TRUE(client_->ok());
  }

  FakeMeterBackend backend_;
  sim::SimControl control_;
  std::unique_ptr<sim::Pr650Endpoint> endpoint_;
  std::unique_ptr<RawClient> client_;
};

TEST_F(Pr650EndpointTest, PathIsAStableLinkToAPtySlave) {
  Start();
  char target[256] = {};
  ASSERT_GT(::readlink(endpoint_->path().c_str(), target, sizeof target - 1), 0);
  EXPECT_EQ(std::string(target), endpoint_->slave_path());
  EXPECT_THAT(endpoint_->slave_path(), StartsWith("/dev/pts/"));
  const std::string path = endpoint_->path();
  endpoint_->Stop();
  EXPECT_NE(::access(path.c_str(), F_OK), 0);  // removed on Stop
}

TEST_F(Pr650EndpointTest, RepliesAreByteExact) {
  Start();
  EXPECT_EQ(client_->Ask("B3\n"), "000\r\n");
  EXPECT_EQ(client_->Ask("D120\n"), "0101,008.0,0380.,0780.,004.\r\n");
  EXPECT_EQ(client_->Ask("D110\n"), "60925301\r\n");
  EXPECT_EQ(client_->Ask("S01,,,,,0,01,1\n"), "00\r\n");
  EXPECT_EQ(client_->Ask("F\n"), "00,100.0\r\n");
  EXPECT_EQ(client_->Ask("M0\n"), "000\r\n");

  const std::string d5 = client_->Ask("D5\n");
  ASSERT_EQ(d5.size(), 6u + 11u + 101u * 17u);
  EXPECT_THAT(d5, StartsWith("00,0\r\n"));
  double integrated = 0;
  for (double v : FakeMeterBackend::Spectrum(0.0123)) integrated += 4 * v;
  char line[32];
  std::snprintf(line, sizeof line, "%.3E\r\n", integrated);
  EXPECT_EQ(d5.substr(6, 11), line);
  EXPECT_EQ(d5.substr(17, 17), "0380.,1.230E-02\r\n");
  EXPECT_EQ(d5.substr(17 + 17, 17), "0384.,1.255E-02\r\n");
  EXPECT_EQ(d5.substr(d5.size() - 17), "0780.,3.690E-02\r\n");
}

TEST_F(Pr650EndpointTest, CommandsInAnyCaseEndedByCrOrLf) {
  Start();
  EXPECT_EQ(client_->Ask("b3\r"), "000\r\n");
  EXPECT_EQ(client_->Ask("d120\r\n"), "0101,008.0,0380.,0780.,004.\r\n");
  EXPECT_EQ(client_->Ask("s01,,,,,500,01,1\n"), "00\r\n");
  EXPECT_EQ(client_->Ask("m0\r"), "000\r\n");
  ASSERT_FALSE(backend_.setups().empty());
  EXPECT_EQ(backend_.setups().back().integration_ms, 500);
}

TEST_F(Pr650EndpointTest, SetupFieldsAreCheckedWithTheBadFieldPosition) {
  Start();
  ASSERT_EQ(client_->Ask("B3\n"), "000\r\n");
  const std::pair<const char*, const char*> cases[] = {
      {"S01,,,,,0,01,1", "00"},    {"S,,,,,0,1,1", "00"},       {"S1,,,,,500,,1", "00"},
      {"S01,,,,100,0,01,1", "00"}, {"S13,,,,,0,01,1", "01"},    {"S02,,,,,0,01,1", "50"},
      {"S01,x,,,,0,01,1", "02"},   {"S01,,,1,,0,01,1", "50"},   {"S01,,,,300,0,01,1", "05"},
      {"S01,,,,,5,01,1", "06"},    {"S01,,,,,6001,01,1", "06"}, {"S01,,,,,0,00,1", "07"},
      {"S01,,,,,0,100,1", "07"},   {"S01,,,,,0,01,2", "08"},    {"S01,,,,,0,01,1,0", "09"},
  };
  for (const auto& [command, reply] : cases) {
    EXPECT_EQ(client_->Ask(std::string(command) + "\n"), std::string(reply) + "\r\n") << command;
  }
  // A rejected setup leaves the previous one in place.
  ASSERT_EQ(client_->Ask("S01,,,,,250,03,1\n"), "00\r\n");
  ASSERT_EQ(client_->Ask("S01,,,,,5,01,1\n"), "06\r\n");
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  EXPECT_EQ(backend_.setups().back().integration_ms, 250);
  EXPECT_EQ(backend_.setups().back().averages, 3);
}

TEST_F(Pr650EndpointTest, UnknownCommandsGetNoReply) {
  Start();
  ASSERT_EQ(client_->Ask("B3\n"), "000\r\n");
  EXPECT_EQ(client_->Ask("M7\n"), "");  // M1–M6 are answered: the simulator has reports 1–6
  EXPECT_EQ(client_->Ask("D111\n"), "");
  EXPECT_EQ(client_->Ask("HELLO\n"), "");
  EXPECT_EQ(client_->Ask("B4\n"), "");
}

TEST_F(Pr650EndpointTest, RemoteModeOnlyWithinTheWakeWindow) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.time_scale.factor = 1;
  o.wake_window_s = 0.2;
  Start(o);
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(client_->Ask("B3\n"), "");
  EXPECT_FALSE(endpoint_->remote_mode());
  // Stand-alone until power-cycled, however often it is asked.
  EXPECT_EQ(client_->Ask("B3\n"), "");

  endpoint_->PowerCycle();
  EXPECT_EQ(client_->Ask("B3\n"), "000\r\n");
  EXPECT_TRUE(endpoint_->remote_mode());
}

TEST_F(Pr650EndpointTest, ZeroWakeWindowMeansAlways) {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.wake_window_s = 0;
  o.time_scale.factor = 1000;  // "5 s" would be over in 5 ms
  Start(o);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(client_->Ask("B3\n"), "000\r\n");
}

TEST_F(Pr650EndpointTest, PowerCycleForgetsTheMeasurementAndSetup) {
  Start();
  ASSERT_EQ(client_->Ask("S01,,,,,250,01,1\n"), "00\r\n");
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  endpoint_->PowerCycle();
  ASSERT_EQ(client_->Ask("B3\n"), "000\r\n");
  // No spectrum without a measurement since power-on (brdf-sim used to send one of zeros).
  EXPECT_EQ(client_->Ask("D5\n"), std::string(sim::kNoMeasurementReply) + "\r\n");
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  EXPECT_EQ(backend_.setups().back().integration_ms, 0);
}

TEST_F(Pr650EndpointTest, SilentFaultAnswersNothing) {
  Start();
  control_.set_serial({.silent = true});
  EXPECT_EQ(client_->Ask("B3\n"), "");
  control_.set_serial({});
  EXPECT_EQ(client_->Ask("B3\n"), "000\r\n");
}

TEST_F(Pr650EndpointTest, InjectedQualityLeadsM0AndD5AndCountsDown) {
  // brdf-sim's older M0 reply, kept as an option: the quality code itself.
  sim::Pr650EndpointOptions options = FastEndpointOptions();
  options.m0_reply_is_quality = true;
  Start(options);
  control_.set_serial({.quality_code = 19, .quality_count = 1});
  EXPECT_EQ(client_->Ask("M0\n"), "019\r\n");
  EXPECT_THAT(client_->Ask("D5\n"), StartsWith("19,0\r\n"));
  EXPECT_EQ(control_.serial().quality_count, 0);
  EXPECT_EQ(client_->Ask("M0\n"), "000\r\n");
}

TEST_F(Pr650EndpointTest, AsTheMeterM0Answers000AndTheQualityIsInTheReports) {
  sim::Pr650EndpointOptions options = FastEndpointOptions();
  options.m0_reply_is_quality = false;
  options.pace_replies = false;
  Start(options);
  control_.set_serial({.quality_code = 18, .quality_count = 1});
  EXPECT_EQ(client_->Ask("M0\n"), "000\r\n");  // what PsychoPy compares with
  EXPECT_THAT(client_->Ask("D5\n"), StartsWith("18,0\r\n"));
  EXPECT_THAT(client_->Ask("D1\n"), StartsWith("18,0,"));
  EXPECT_THAT(client_->Ask("D2\n"), StartsWith("18,0,"));
}

TEST_F(Pr650EndpointTest, GarbageAndTruncationKeepTheReplysShapeOrCutIt) {
  Start();
  control_.set_serial({.garbage_next = 1});
  const std::string garbage = client_->Ask("D120\n");
  EXPECT_EQ(garbage.size(), std::string("0101,008.0,0380.,0780.,004.\r\n").size());
  EXPECT_NE(garbage, "0101,008.0,0380.,0780.,004.\r\n");
  EXPECT_THAT(garbage, ::testing::EndsWith("\r\n"));

  control_.set_serial({.truncate_next = 1});
  EXPECT_EQ(client_->Ask("D120\n"), "0101,008.0,038");  // the first half
  EXPECT_EQ(control_.serial().truncate_next, 0);
  EXPECT_EQ(client_->Ask("D120\n"), "0101,008.0,0380.,0780.,004.\r\n");
}

TEST_F(Pr650EndpointTest, RepliesArePacedAtTheSerialRate) {
  Start();  // 10x time: 1734 bytes at 960 bytes/s are 1.8 s simulated, 0.18 s real
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  const auto start = SteadyClock::now();
  const std::string d5 = client_->Ask("D5\n", 60ms);
  EXPECT_EQ(d5.size(), 1734u);
  EXPECT_GE(SteadyClock::now() - start, 170ms);
}

TEST_F(Pr650EndpointTest, PacedRepliesReachThePortInFifoBursts) {
  Start();  // fifo_bytes 14 (a 16550's receive FIFO): ~124 bursts for the D5 report
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  const auto start = SteadyClock::now();
  EXPECT_EQ(client_->Ask("D5\n", 60ms).size(), 1734u);
  EXPECT_GE(SteadyClock::now() - start, 170ms);  // the same pace on the wire
  const std::vector<std::size_t> reads = client_->reads;
  ASSERT_FALSE(reads.empty());
  for (std::size_t i = 0; i + 1 < reads.size(); ++i) {
    EXPECT_GE(reads[i], 14u) << "read " << i << " of " << reads.size();  // never a part burst
  }
  EXPECT_LE(reads.size(), 1734u / 14 + 1);

  // Byte by byte: as many reads as the client can tell apart, far more than bursts.
  endpoint_.reset();
  sim::Pr650EndpointOptions options = FastEndpointOptions();
  options.fifo_bytes = 1;
  Start(options);
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  EXPECT_EQ(client_->Ask("D5\n", 60ms).size(), 1734u);
  EXPECT_GT(client_->reads.size(), 1734u / 14 + 1);
}

TEST_F(Pr650EndpointTest, VanishingPortHangsUpAndComesBackAtTheSameLink) {
  Start();
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  control_.set_serial({.vanish_seconds = 2.0});  // 0.2 s real
  const std::string partial = client_->Ask("D5\n");
  EXPECT_TRUE(client_->hangup);
  EXPECT_GT(partial.size(), 0u);
  EXPECT_LT(partial.size(), 1734u);
  EXPECT_EQ(control_.serial().vanish_seconds, 0);

  const auto end = SteadyClock::now() + 3s;
  while (::access(endpoint_->path().c_str(), F_OK) != 0 && SteadyClock::now() < end) {
    std::this_thread::sleep_for(10ms);
  }
  RawClient again(endpoint_->path());
  ASSERT_TRUE(again.ok());
  // The meter itself stayed on: still in remote mode, still holding its measurement. The first
  // exchange on the new link waits up to a second for the endpoint to be reading it again (under
  // load its thread may take longer than the usual 80 ms quiet gap to come back).
  EXPECT_EQ(again.Ask("B3\n", 1s), "000\r\n");
  EXPECT_EQ(again.Ask("D5\n", 1s).size(), 1734u);
}

// ---- the remote command set the open drivers use, read with brdfd's own parsers ---------------

// The meter's own M0 reply (000), and replies as fast as the pty takes them: a whole report is
// read in one Ask even on a loaded machine.
sim::Pr650EndpointOptions MeterOptions() {
  sim::Pr650EndpointOptions o = FastEndpointOptions();
  o.m0_reply_is_quality = false;
  o.pace_replies = false;
  return o;
}

// The flat-ish test spectrum's colorimetry, as the simulated meter computes it.
sim::Pr650Tristimulus TestSpectrumTristimulus() {
  return sim::Pr650TristimulusOf(FakeMeterBackend::Spectrum(0.0123));
}

// Relative agreement at the meter's 4 significant digits.
void ExpectNear4(double got, double want) {
  EXPECT_NEAR(got, want, std::abs(want) * 6e-4) << "want " << want;
}

TEST_F(Pr650EndpointTest, M1AndD1ReportLuminanceAndXyThatBrdfdsParserReads) {
  Start(MeterOptions());
  const std::string m1 = client_->Ask("M1\n");
  auto r = drivers::pr650::ParseColorimetryReply(m1);
  ASSERT_TRUE(r.ok()) << r.status().ToString() << " in " << m1;
  const sim::Pr650Tristimulus t = TestSpectrumTristimulus();
  const double sum = t.X + t.Y + t.Z;
  EXPECT_EQ(r->quality_code, 0);
  EXPECT_EQ(r->units_code, 0);
  ExpectNear4(r->luminance, t.Y);
  EXPECT_NEAR(r->x, t.X / sum, 1e-4);
  EXPECT_NEAR(r->y, t.Y / sum, 1e-4);
  EXPECT_GT(r->luminance, 0);
  EXPECT_EQ(client_->Ask("D1\n"), m1);      // the held measurement again
  ASSERT_EQ(backend_.setups().size(), 1u);  // D1 does not measure
}

TEST_F(Pr650EndpointTest, M2AndD2ReportXyzThatBrdfdsParserReads) {
  Start(MeterOptions());
  const std::string m2 = client_->Ask("M2\n");
  // The columns Psychtoolbox's PR650measxyz cuts: X at 6–14, Y at 16–24, Z at 26–34 (1-based).
  ASSERT_EQ(m2.size(), 34u + 2u) << m2;
  auto r = drivers::pr650::ParseTristimulusReply(m2);
  ASSERT_TRUE(r.ok()) << r.status().ToString() << " in " << m2;
  const sim::Pr650Tristimulus t = TestSpectrumTristimulus();
  ExpectNear4(r->X, t.X);
  ExpectNear4(r->Y, t.Y);
  ExpectNear4(r->Z, t.Z);
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  auto again = drivers::pr650::ParseTristimulusReply(client_->Ask("D2\n"));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->Y, r->Y);
  EXPECT_EQ(backend_.setups().size(), 2u);
}

TEST_F(Pr650EndpointTest, M3ReportsLuminanceAndUPrimeVPrime) {
  Start(MeterOptions());
  const std::string m3 = client_->Ask("M3\n");
  const sim::Pr650Tristimulus t = TestSpectrumTristimulus();
  const double d = t.X + 15 * t.Y + 3 * t.Z;
  char want[64];
  std::snprintf(want, sizeof want, "00,0,%.3E,.%04ld,.%04ld\r\n", t.Y,
                std::lround(4 * t.X / d * 1e4), std::lround(9 * t.Y / d * 1e4));
  EXPECT_EQ(m3, want);
}

TEST_F(Pr650EndpointTest, M5IsTheMeasurementAndTheSpectrumInOneReply) {
  Start(MeterOptions());
  const std::string m5 = client_->Ask("M5\n");
  auto r = drivers::pr650::ParseSpectrumReply(m5, WavelengthGrid::Pr650(), "M5");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->values.size(), 101u);
  EXPECT_EQ(client_->Ask("D5\n"), m5);
}

TEST_F(Pr650EndpointTest, NoReportBeforeAMeasurement) {
  Start(MeterOptions());
  for (const char* report : {"D1\n", "D2\n", "D3\n", "D5\n"}) {
    EXPECT_EQ(client_->Ask(report), std::string(sim::kNoMeasurementReply) + "\r\n") << report;
  }
  EXPECT_TRUE(backend_.setups().empty());
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  EXPECT_THAT(client_->Ask("D5\n"), StartsWith("00,0\r\n"));
  // Switched off and on: the measurement is gone.
  endpoint_->PowerCycle();
  EXPECT_EQ(client_->Ask("D5\n"), std::string(sim::kNoMeasurementReply) + "\r\n");
}

TEST_F(Pr650EndpointTest, ReportsFourAndSixAndD201AsTheOpenDriversParseThem) {
  Start(MeterOptions());
  // Mcalibrator2: a bare S, then D201 repeats the setup's reply.
  ASSERT_EQ(client_->Ask("S\n"), "00\r\n");
  EXPECT_EQ(client_->Ask("D201\n"), "00\r\n");
  ASSERT_EQ(client_->Ask("S1,,,,,5,,1\n"), "06\r\n");
  EXPECT_EQ(client_->Ask("D201\n"), "06\r\n");
  const std::string m6 = client_->Ask("M6\n");
  const sim::Pr650Tristimulus t = TestSpectrumTristimulus();
  const double sum = t.X + t.Y + t.Z;
  const double d = t.X + 15 * t.Y + 3 * t.Z;
  char want[96];
  std::snprintf(want, sizeof want, "00,0,%.3E,.%04ld,.%04ld,.%04ld,.%04ld\r\n", t.Y,
                std::lround(t.X / sum * 1e4), std::lround(t.Y / sum * 1e4),
                std::lround(4 * t.X / d * 1e4), std::lround(9 * t.Y / d * 1e4));
  EXPECT_EQ(m6, want);
  EXPECT_EQ(client_->Ask("D06\n"), m6);  // response codes by value
  // D4: luminance, colour temperature (K), deviation; fields as a float() parser splits them.
  const std::string d4 = client_->Ask("D4\n");
  std::vector<std::string> fields;
  std::stringstream split(d4.substr(0, d4.find('\r')));
  for (std::string f; std::getline(split, f, ',');) fields.push_back(f);
  ASSERT_EQ(fields.size(), 5u) << d4;
  const sim::Pr650ColourTemperature ct = sim::Pr650ColourTemperatureOf(t.X / sum, t.Y / sum);
  EXPECT_NEAR(std::stod(fields[3]), ct.kelvin, ct.kelvin * 1e-3);
  EXPECT_GT(ct.kelvin, 1000);
  EXPECT_NEAR(std::stod(fields[4]), ct.duv, 1e-4);
  EXPECT_EQ(backend_.setups().size(), 1u);  // D4, D6 and D201 did not measure
}

TEST_F(Pr650EndpointTest, ColourTemperatureOfKnownIlluminants) {
  // D65 (x .3127, y .3290): about 6,500 K, just above the locus; illuminant A: 2,856 K, on it.
  const sim::Pr650ColourTemperature d65 = sim::Pr650ColourTemperatureOf(0.3127, 0.3290);
  EXPECT_NEAR(d65.kelvin, 6504, 15);
  EXPECT_NEAR(d65.duv, 0.0032, 0.0005);
  const sim::Pr650ColourTemperature a = sim::Pr650ColourTemperatureOf(0.4476, 0.4074);
  EXPECT_NEAR(a.kelvin, 2856, 15);
  EXPECT_NEAR(a.duv, 0.0, 0.0005);
}

TEST_F(Pr650EndpointTest, NoDataAndUnitsCodeFaultsShowInTheReports) {
  Start(MeterOptions());
  control_.set_serial({.no_data_next = 1, .units_code = 2});
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  EXPECT_EQ(client_->Ask("D5\n"), "-1\r\n");
  EXPECT_EQ(client_->Ask("M5\n").substr(0, 6), "00,2\r\n");
  EXPECT_EQ(control_.serial().no_data_next, 0);
  EXPECT_THAT(client_->Ask("D1\n"), StartsWith("00,2,"));
}

TEST_F(Pr650EndpointTest, TheBareCrHeaderVariantRunsQualityIntoTheIntensityLine) {
  sim::Pr650EndpointOptions options = MeterOptions();
  options.quirks.d5_header_bare_cr = true;
  Start(options);
  ASSERT_EQ(client_->Ask("M0\n"), "000\r\n");
  const std::string d5 = client_->Ask("D5\n");
  EXPECT_THAT(d5, StartsWith("00,0\r"));
  EXPECT_NE(d5[5], '\n');
  auto r = drivers::pr650::ParseSpectrumReply(d5, WavelengthGrid::Pr650());
  ASSERT_TRUE(r.ok()) << r.status().ToString();
}

}  // namespace
}  // namespace brdf::testing
