// brdf-sim as a process: the start-up lines other tests rely on, the endpoints they name, the
// control unit, a measurement through the simulated PR-650's pty, clean exit on SIGTERM, and the
// `truth` subcommand.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "tests/support/sim/modbus_control.h"
#include "tests/support/sim/process.h"
#include "tests/support/test_env.h"
#include "tools/brdf-sim/optics/optics.h"

namespace brdf::sim {
namespace {

using brdf::testing::ModbusControl;
using brdf::testing::RunBrdfSim;
using brdf::testing::SimProcess;
using namespace std::chrono_literals;

// Fast, quiet, deterministic: simulated time 50× real, no 9600-baud pacing, remote mode at any
// time after power-on.
std::vector<std::string> FastArgs(std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"--time-scale", "50", "--no-pacing", "--wake-window", "0",
                                   "--seed",       "3",  "--log-level", "warn"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::unique_ptr<SimProcess> StartSim(std::vector<std::string> extra = {}) {
  auto sim = SimProcess::Start(FastArgs(std::move(extra)));
  EXPECT_TRUE(sim.ok()) << sim.status().ToString();
  return sim.ok() ? std::move(sim).value() : nullptr;
}

bool TcpAccepts(const std::string& host, int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  ::inet_pton(AF_INET, host.c_str(), &addr.sin_addr);
  const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  ::close(fd);
  return ok;
}

// A bare PR-650 conversation over the pty: send a command, collect reply lines.
class MeterPort {
 public:
  explicit MeterPort(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd_ < 0) return;
    termios t{};
    ::tcgetattr(fd_, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(fd_, TCSANOW, &t);
  }
  ~MeterPort() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool is_open() const { return fd_ >= 0; }

  // Sends `command` + LF and reads until `lines` CR LF-ended lines arrived or `timeout` passed.
  std::vector<std::string> Ask(const std::string& command, std::size_t lines,
                               std::chrono::milliseconds timeout = 5s) {
    const std::string out = command + "\n";
    EXPECT_EQ(::write(fd_, out.data(), out.size()), static_cast<ssize_t>(out.size()));
    std::vector<std::string> got;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (got.size() < lines && std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      char buf[512];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) continue;
      pending_.append(buf, static_cast<std::size_t>(n));
      for (std::size_t end; (end = pending_.find("\r\n")) != std::string::npos;) {
        got.push_back(pending_.substr(0, end));
        pending_.erase(0, end + 2);
      }
    }
    return got;
  }

 private:
  int fd_ = -1;
  std::string pending_;
};

// The 101 radiance values of a D5 reply ("qq,U", integrated, then "0380.,r.rrrEsee" lines).
std::vector<double> SpectrumOf(const std::vector<std::string>& d5) {
  std::vector<double> out;
  for (std::size_t i = 2; i < d5.size(); ++i) {
    const std::size_t comma = d5[i].find(',');
    if (comma != std::string::npos) out.push_back(std::strtod(d5[i].c_str() + comma + 1, nullptr));
  }
  return out;
}

TEST(SimProcessTest, PrintsTheStartUpContractInOrder) {
  auto sim = StartSim({"--rtu"});
  ASSERT_NE(sim, nullptr);
  const auto& lines = sim->startup_lines();
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].rfind("pr650 /", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1],
            "modbus-tcp " + sim->modbus_host() + ":" + std::to_string(sim->modbus_port()));
  EXPECT_EQ(lines[2], "modbus-rtu " + sim->rtu_path());
  EXPECT_EQ(lines[3], "control-unit 100");
  EXPECT_EQ(lines[4], "ready");
  EXPECT_NE(sim->modbus_port(), 0);
}

TEST(SimProcessTest, EndpointsAcceptConnections) {
  auto sim = StartSim({"--rtu"});
  ASSERT_NE(sim, nullptr);
  EXPECT_TRUE(TcpAccepts(sim->modbus_host(), sim->modbus_port()));
  for (const std::string& path : {sim->pr650_path(), sim->rtu_path()}) {
    const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
    ASSERT_GE(fd, 0) << path;
    EXPECT_TRUE(::isatty(fd)) << path;
    ::close(fd);
  }
}

TEST(SimProcessTest, WithoutRtuThereIsNoRtuLine) {
  auto sim = StartSim();
  ASSERT_NE(sim, nullptr);
  EXPECT_EQ(sim->startup_lines().size(), 4u);
  EXPECT_TRUE(sim->rtu_path().empty());
}

TEST(SimProcessTest, UsesTheRequestedPort) {
  auto port = brdf::testing::FreeTcpPort();
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  auto sim = StartSim({"--modbus-port", std::to_string(*port)});
  ASSERT_NE(sim, nullptr);
  EXPECT_EQ(sim->modbus_port(), *port);
}

TEST(SimProcessTest, StopsCleanlyOnSigterm) {
  auto sim = StartSim();
  ASSERT_NE(sim, nullptr);
  auto code = sim->Stop();
  ASSERT_TRUE(code.ok()) << code.status().ToString();
  EXPECT_EQ(*code, 0);
}

TEST(SimProcessTest, BadFlagFailsBeforeAnyStartUpLine) {
  auto r = RunBrdfSim({"--time-scale", "-1"});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_NE(r->exit_code, 0);
  EXPECT_TRUE(r->out.empty()) << r->out;
  EXPECT_NE(r->err.find("time scale"), std::string::npos) << r->err;
}

TEST(SimProcessTest, ControlUnitSetsMountedTargetAndFaults) {
  auto sim = StartSim({"--mounted", "white"});
  ASSERT_NE(sim, nullptr);
  auto control =
      ModbusControl::Connect(sim->modbus_host(), sim->modbus_port(), sim->control_unit());
  ASSERT_TRUE(control.ok()) << control.status().ToString();
  auto& c = **control;
  auto mounted = c.Mounted();
  ASSERT_TRUE(mounted.ok()) << mounted.status().ToString();
  EXPECT_EQ(*mounted, MountedTarget::kWhite);  // from the flag
  ASSERT_TRUE(c.SetMounted(MountedTarget::kDark).ok());
  EXPECT_EQ(*c.Mounted(), MountedTarget::kDark);

  SerialFaults f;
  f.garbage_next = 2;
  f.quality_code = 18;
  f.quality_count = 3;
  f.vanish_seconds = 1.5;
  ASSERT_TRUE(c.SetSerialFaults(f).ok());
  auto back = c.SerialFaults();
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->garbage_next, 2);
  EXPECT_EQ(back->quality_code, 18);
  EXPECT_EQ(back->quality_count, 3);
  EXPECT_EQ(back->vanish_seconds, 1.5);
  ASSERT_TRUE(c.SetSerialFaults({}).ok());
  EXPECT_EQ(c.SerialFaults()->quality_count, 0);
}

// End to end through the pty: the white standard at the stage's rest pose (all axes at 0: normal
// incidence) reads E(λ)·0.99/π + ambient, as the optics say.
TEST(SimProcessTest, MeasuresTheWhiteStandardThroughThePty) {
  auto sim = StartSim({"--mounted", "white"});
  ASSERT_NE(sim, nullptr);
  MeterPort meter(sim->pr650_path());
  ASSERT_TRUE(meter.is_open());
  ASSERT_EQ(meter.Ask("B0", 1), std::vector<std::string>{"000"});
  ASSERT_EQ(meter.Ask("S01,,,,,0,01,1", 1), std::vector<std::string>{"00"});
  ASSERT_EQ(meter.Ask("M0", 1), std::vector<std::string>{"000"});
  const auto d5 = meter.Ask("D5", 103);
  ASSERT_EQ(d5.size(), 103u);
  EXPECT_EQ(d5[0].substr(0, 2), "00");
  const std::vector<double> radiance = SpectrumOf(d5);
  ASSERT_EQ(radiance.size(), 101u);

  // The same model, in-process, at the same pose.
  class RestPose final : public StagePoseSource {
   public:
    Pose LivePose() const override { return Pose{}; }
  } rest;
  SimControl control;
  RigOptics optics(rest, control, OpticsConfig{});
  const auto expected = optics.ExpectedRadiance(MountedTarget::kWhite, Pose{});
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  // The integration time adaptive mode picks for this scene (S…,0,… above), for the noise.
  const int integration_ms =
      optics.detector()
          .ChooseExposure(*std::max_element(expected.begin(), expected.end()), MeterSetup{})
          .integration_ms;
  for (std::size_t k = 0; k < radiance.size(); ++k) {
    const double e = optics.lamp().Irradiance(grid.at(k)) * 0.99 / std::numbers::pi +
                     optics.config().ambient_radiance;
    EXPECT_NEAR(expected[k], e, 1e-12 * e);
    // 4 significant digits on the wire, plus the noise.
    const double tol = 5e-4 * e + 5 * optics.detector().NoiseSigma(e, integration_ms, 1);
    EXPECT_NEAR(radiance[k], e, tol) << grid.at(k) << " nm";
  }
}

// The sample-fixed method: once lamp and detector are placed by hand (control registers 29–33), the
// sample reads at those directions, not at the holder's pose; register 29 = 0 returns to the pose.
// Out-of-range directions are refused whole (exception 03), leaving the placement as it was.
TEST(SimProcessTest, LampAndDetectorPlacedByHandSetTheDirections) {
  auto sim = StartSim({"--mounted", "sample"});
  ASSERT_NE(sim, nullptr);
  auto control =
      ModbusControl::Connect(sim->modbus_host(), sim->modbus_port(), sim->control_unit());
  ASSERT_TRUE(control.ok()) << control.status().ToString();
  auto& c = **control;
  // θi 60°, φi 0°, θo 30°, φo −150°, in signed centidegrees.
  const std::vector<std::uint16_t> placed = {1, 6000, 0, 3000,
                                             static_cast<std::uint16_t>(std::int16_t{-15000})};
  ASSERT_TRUE(c.WriteRegisters(29, placed).ok());
  auto back = c.ReadRegisters(29, 5);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(*back, placed);
  const std::vector<std::uint16_t> too_far = {9100};  // θi 91°
  EXPECT_FALSE(c.WriteRegisters(30, too_far).ok());
  EXPECT_EQ(*c.ReadRegisters(29, 5), placed);

  MeterPort meter(sim->pr650_path());
  ASSERT_TRUE(meter.is_open());
  ASSERT_EQ(meter.Ask("B0", 1), std::vector<std::string>{"000"});
  ASSERT_EQ(meter.Ask("S01,,,,,0,01,1", 1), std::vector<std::string>{"00"});
  auto measure = [&] {
    EXPECT_EQ(meter.Ask("M0", 1), std::vector<std::string>{"000"});
    return SpectrumOf(meter.Ask("D5", 103));
  };
  const std::vector<double> by_hand = measure();

  class RestPose final : public StagePoseSource {
   public:
    Pose LivePose() const override { return Pose{}; }
  } rest;
  SimControl sim_control;
  RigOptics optics(rest, sim_control, OpticsConfig{});
  const auto at_placed =
      optics.ExpectedRadianceAt(MountedTarget::kSample, Directions{60, 0, 30, -150});
  const auto at_rest = optics.ExpectedRadiance(MountedTarget::kSample, Pose{});
  ASSERT_EQ(by_hand.size(), at_placed.size());
  const std::size_t k550 = 42;
  EXPECT_NEAR(by_hand[k550], at_placed[k550], 0.02 * at_placed[k550]);
  // The holder at rest is normal incidence, a different reading by far.
  EXPECT_GT(std::abs(at_rest[k550] - at_placed[k550]), 0.2 * at_placed[k550]);

  ASSERT_TRUE(c.WriteRegisters(29, std::vector<std::uint16_t>{0}).ok());
  const std::vector<double> from_pose = measure();
  EXPECT_NEAR(from_pose[k550], at_rest[k550], 0.02 * at_rest[k550]);
}

// An injected quality code shows in exactly the next N measurements' status.
TEST(SimProcessTest, InjectedQualityCodeReachesTheMeterForTheNextMeasurementsOnly) {
  auto sim = StartSim({"--mounted", "white"});
  ASSERT_NE(sim, nullptr);
  auto control =
      ModbusControl::Connect(sim->modbus_host(), sim->modbus_port(), sim->control_unit());
  ASSERT_TRUE(control.ok()) << control.status().ToString();
  SerialFaults f;
  f.quality_code = 29;
  f.quality_count = 2;
  ASSERT_TRUE((*control)->SetSerialFaults(f).ok());
  MeterPort meter(sim->pr650_path());
  ASSERT_EQ(meter.Ask("B0", 1), std::vector<std::string>{"000"});
  // As on the meter, M0 answers 000 and the quality is in the report.
  EXPECT_EQ(meter.Ask("M0", 1), std::vector<std::string>{"000"});
  EXPECT_EQ(meter.Ask("D5", 103)[0], "29,0");
  // M5 measures too (and counts down the fault); its reply is the D5 report, quality code first.
  const auto m5 = meter.Ask("M5", 103);
  ASSERT_EQ(m5.size(), 103u);
  EXPECT_EQ(m5[0], "29,0");
  EXPECT_EQ(SpectrumOf(m5).size(), 101u);
  EXPECT_EQ(meter.Ask("M5", 103)[0], "00,0");
  EXPECT_EQ(meter.Ask("M0", 1), std::vector<std::string>{"000"});
  EXPECT_EQ((*control)->SerialFaults()->quality_count, 0);
}

TEST(SimProcessTest, TheOlderM0ReplyCarryingTheQualityIsAnOption) {
  auto sim = StartSim({"--pr650-m0-quality", "--serial-quality-code", "18"});
  ASSERT_NE(sim, nullptr);
  MeterPort meter(sim->pr650_path());
  ASSERT_EQ(meter.Ask("B0", 1), std::vector<std::string>{"000"});
  EXPECT_EQ(meter.Ask("M0", 1), std::vector<std::string>{"018"});
  EXPECT_EQ(meter.Ask("D5", 103)[0], "18,0");
}

std::vector<double> ParseTextTruth(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::vector<double> values;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double nm = 0, f = 0;
    if (fields >> nm >> f) values.push_back(f);
  }
  return values;
}

TEST(SimProcessTest, TruthSubcommandPrintsTheTrueBrdf) {
  auto r = RunBrdfSim({"truth", "--theta-i", "30", "--theta-o", "45", "--phi", "150"});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->exit_code, 0) << r->err;
  EXPECT_EQ(ParseTextTruth(r->out), TrueBrdf(Directions{30, 0, 45, 150}));

  auto aniso = RunBrdfSim({"truth", "--theta-i", "30", "--theta-o", "45", "--phi-i", "20",
                           "--phi-o", "190", "--anisotropic", "--json"});
  ASSERT_TRUE(aniso.ok()) << aniso.status().ToString();
  ASSERT_EQ(aniso->exit_code, 0) << aniso->err;
  const std::string& json = aniso->out;
  const std::size_t start = json.find("\"brdf\":[");
  ASSERT_NE(start, std::string::npos) << json;
  std::vector<double> values;
  const char* p = json.c_str() + start + 8;
  while (*p != ']' && *p != '\0') {
    char* end = nullptr;
    values.push_back(std::strtod(p, &end));
    p = *end == ',' ? end + 1 : end;
  }
  EXPECT_EQ(values, TrueBrdf(Directions{30, 20, 45, 190}, true));
}

TEST(SimProcessTest, TruthAtTheLivePoseMatchesTheGeometry) {
  // The truth subcommand takes directions; a pose's directions come from core/geometry.h. A
  // specular pose (α = 0, β = δ/2) has θi = θo = β and φ = 180.
  const Directions d = PoseToDirections(Pose{0, 25, 0, 50});
  const IsoDirection iso = ToIsotropic(d);
  auto r = RunBrdfSim({"truth", "--theta-i", std::to_string(iso.theta_i), "--theta-o",
                       std::to_string(iso.theta_o), "--phi", std::to_string(iso.phi)});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const auto printed = ParseTextTruth(r->out);
  const auto truth = TrueBrdf(d);
  ASSERT_EQ(printed.size(), truth.size());
  for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_NEAR(printed[k], truth[k], 1e-6 * truth[k]);
}

}  // namespace
}  // namespace brdf::sim
