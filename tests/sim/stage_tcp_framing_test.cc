// brdf-sim's Modbus TCP endpoint through a raw socket, byte by byte: requests are framed by the
// MBAP length (a malformed PDU gets an exception and the connection stays in step), a non-zero
// protocol id is dropped, an unframeable length closes the connection; the drives answer only the
// function codes the AZ documents (FC04 refused, FC08 echoed); exception 04 can be injected; the
// control unit's outage refuses connections for a while and its word-order swap takes effect.
// The drives' own settings (word order, ramp unit) are in stage_drive_settings_test.cc.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "tools/brdf-sim/stage/rtu_frame.h"
#include "tools/brdf-sim/stage/simulator.h"

namespace brdf::sim {
namespace {

using Bytes = std::vector<std::uint8_t>;
using SteadyClock = std::chrono::steady_clock;

// An ADU: transaction id, protocol id, length (unit + PDU), unit id, PDU.
Bytes Adu(std::uint16_t transaction, std::uint8_t unit, const Bytes& pdu,
          std::uint16_t protocol = 0) {
  const auto length = static_cast<std::uint16_t>(pdu.size() + 1);
  Bytes out{static_cast<std::uint8_t>(transaction >> 8),
            static_cast<std::uint8_t>(transaction),
            static_cast<std::uint8_t>(protocol >> 8),
            static_cast<std::uint8_t>(protocol),
            static_cast<std::uint8_t>(length >> 8),
            static_cast<std::uint8_t>(length),
            unit};
  out.insert(out.end(), pdu.begin(), pdu.end());
  return out;
}

// FC03 of the AZ status word (0x007E, two registers).
const Bytes kReadStatus{0x03, 0x00, 0x7E, 0x00, 0x02};

class RawModbusClient {
 public:
  explicit RawModbusClient(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~RawModbusClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }

  bool Send(const Bytes& bytes) {
    return ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) ==
           static_cast<ssize_t>(bytes.size());
  }

  // One whole reply ADU (framed by its MBAP length), or empty after `timeout` or when the server
  // closed the connection (then closed() is true).
  Bytes ReadAdu(std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) {
    const auto end = SteadyClock::now() + timeout;
    while (SteadyClock::now() < end) {
      if (input_.size() >= 6) {
        const std::size_t size = 6u + ((input_[4] << 8) | input_[5]);
        if (input_.size() >= size) {
          Bytes adu(input_.begin(), input_.begin() + static_cast<std::ptrdiff_t>(size));
          input_.erase(input_.begin(), input_.begin() + static_cast<std::ptrdiff_t>(size));
          return adu;
        }
      }
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 10) <= 0) continue;
      std::uint8_t buffer[512];
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n <= 0) {
        closed_ = true;
        return {};
      }
      input_.insert(input_.end(), buffer, buffer + n);
    }
    return {};
  }
  bool closed() const { return closed_; }

 private:
  int fd_ = -1;
  Bytes input_;
  bool closed_ = false;
};

std::uint16_t TransactionOf(const Bytes& adu) {
  return static_cast<std::uint16_t>((adu.at(0) << 8) | adu.at(1));
}
Bytes PduOf(const Bytes& adu) {
  return Bytes(adu.begin() + 7, adu.end());
}

class StageTcpFramingTest : public ::testing::Test {
 protected:
  void Start(StageSimConfig config = {}) {
    config.serve_rtu = false;
    config.time_scale.factor = 50;
    stage_ = std::make_unique<StageSimulator>(config, control_);
    std::string error;
    ASSERT_TRUE(stage_->Start(&error)) << error;
    client_ = std::make_unique<RawModbusClient>(stage_->tcp_port());
    ASSERT_TRUE(client_->ok());
  }

  // Sends one ADU and returns the reply's PDU, checking its transaction id and unit.
  Bytes Ask(std::uint16_t transaction, std::uint8_t unit, const Bytes& pdu) {
    EXPECT_TRUE(client_->Send(Adu(transaction, unit, pdu)));
    const Bytes reply = client_->ReadAdu();
    if (reply.size() < 8) {
      ADD_FAILURE() << "no reply to transaction " << transaction;
      return {};
    }
    EXPECT_EQ(TransactionOf(reply), transaction);
    EXPECT_EQ(reply[2], 0);  // protocol id
    EXPECT_EQ(reply[3], 0);
    EXPECT_EQ(reply[6], unit);
    return PduOf(reply);
  }

  SimControl control_;
  std::unique_ptr<StageSimulator> stage_;
  std::unique_ptr<RawModbusClient> client_;
};

TEST_F(StageTcpFramingTest, AMalformedPduGetsAnExceptionAndTheNextReplyIsInStep) {
  Start();
  // FC16 whose byte count (4) claims more data than the ADU holds (2 bytes): a reader that trusts
  // the byte count swallows the next request's header. Framed by the MBAP length it is exception
  // 03, and the following read keeps its own transaction id and unit.
  const Bytes bad_write{0x10, 0x00, 0x58, 0x00, 0x02, 0x04, 0x00, 0x01};
  Bytes both = Adu(0x1111, 1, bad_write);
  const Bytes next = Adu(0x2222, 2, kReadStatus);
  both.insert(both.end(), next.begin(), next.end());
  ASSERT_TRUE(client_->Send(both));  // one segment: the two ADUs back to back

  const Bytes first = client_->ReadAdu();
  ASSERT_EQ(first.size(), 9u);
  EXPECT_EQ(TransactionOf(first), 0x1111);
  EXPECT_EQ(first[6], 1);
  EXPECT_EQ(PduOf(first), (Bytes{0x90, 0x03}));

  const Bytes second = client_->ReadAdu();
  ASSERT_GE(second.size(), 8u);
  EXPECT_EQ(TransactionOf(second), 0x2222);
  EXPECT_EQ(second[6], 2);
  EXPECT_EQ(PduOf(second)[0], 0x03);
  EXPECT_EQ(PduOf(second)[1], 4);  // two registers

  // A read with trailing bytes in its ADU: exception 03, still in step.
  EXPECT_EQ(Ask(0x3333, 1, {0x03, 0x00, 0x7E, 0x00, 0x02, 0xAA, 0xBB}), (Bytes{0x83, 0x03}));
  EXPECT_EQ(Ask(0x4444, 3, kReadStatus)[0], 0x03);
}

TEST_F(StageTcpFramingTest, AnAduSplitAcrossSegmentsIsOneRequest) {
  Start();
  const Bytes adu = Adu(0x0102, 1, kReadStatus);
  ASSERT_TRUE(client_->Send(Bytes(adu.begin(), adu.begin() + 4)));
  EXPECT_TRUE(client_->ReadAdu(std::chrono::milliseconds(100)).empty());  // nothing yet
  EXPECT_FALSE(client_->closed());
  ASSERT_TRUE(client_->Send(Bytes(adu.begin() + 4, adu.end())));
  const Bytes reply = client_->ReadAdu();
  ASSERT_GE(reply.size(), 8u);
  EXPECT_EQ(TransactionOf(reply), 0x0102);
}

TEST_F(StageTcpFramingTest, ANonZeroProtocolIdIsDroppedWithoutAReply) {
  Start();
  Bytes both = Adu(0x0AAA, 1, kReadStatus, /*protocol=*/1);
  const Bytes next = Adu(0x0BBB, 1, kReadStatus);
  both.insert(both.end(), next.begin(), next.end());
  ASSERT_TRUE(client_->Send(both));
  const Bytes reply = client_->ReadAdu();
  ASSERT_GE(reply.size(), 8u);
  EXPECT_EQ(TransactionOf(reply), 0x0BBB);  // the first one got no reply at all
  EXPECT_TRUE(client_->ReadAdu(std::chrono::milliseconds(100)).empty());
  EXPECT_FALSE(client_->closed());
}

TEST_F(StageTcpFramingTest, AnUnframeableLengthClosesTheConnection) {
  Start();
  // Length 0: not even a unit id. No start marker to resync on, so the server hangs up.
  ASSERT_TRUE(client_->Send({0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x01, 0x03}));
  EXPECT_TRUE(client_->ReadAdu().empty());
  EXPECT_TRUE(client_->closed());

  // Length 300: more than the 253-byte PDU maximum.
  client_ = std::make_unique<RawModbusClient>(stage_->tcp_port());
  ASSERT_TRUE(client_->ok());
  ASSERT_TRUE(client_->Send({0x00, 0x02, 0x00, 0x00, 0x01, 0x2C, 0x01, 0x03}));
  EXPECT_TRUE(client_->ReadAdu().empty());
  EXPECT_TRUE(client_->closed());

  // A new connection is served as usual.
  client_ = std::make_unique<RawModbusClient>(stage_->tcp_port());
  ASSERT_TRUE(client_->ok());
  EXPECT_EQ(Ask(0x0003, 1, kReadStatus)[0], 0x03);
}

TEST_F(StageTcpFramingTest, TheAzDrivesAnswerOnlyTheFunctionCodesTheAzDocuments) {
  Start();
  EXPECT_EQ(Ask(1, 1, {0x04, 0x00, 0x7E, 0x00, 0x02}), (Bytes{0x84, 0x01}));  // FC04 refused
  EXPECT_EQ(Ask(2, 1, {0x01, 0x00, 0x00, 0x00, 0x08}), (Bytes{0x81, 0x01}));  // coils: none
  EXPECT_EQ(Ask(3, 1, kReadStatus)[0], 0x03);
  // The control unit is brdf-sim's own: it answers everything brdf-sim serves.
  EXPECT_EQ(Ask(4, 100, {0x04, 0x00, 0x00, 0x00, 0x01})[0], 0x04);
}

TEST_F(StageTcpFramingTest, AnotherDrivesFunctionCodesCanBeChosen) {
  StageSimConfig config;
  config.drive_function_codes = *DocumentedFunctionCodes("moons");
  Start(config);
  EXPECT_EQ(Ask(1, 1, {0x04, 0x00, 0x7E, 0x00, 0x02})[0], 0x04);              // MOONS' reads 04
  EXPECT_EQ(Ask(2, 1, {0x08, 0x00, 0x00, 0x12, 0x34}), (Bytes{0x88, 0x01}));  // but no FC08
}

TEST_F(StageTcpFramingTest, Fc08ReturnQueryDataEchoesAndOtherSubFunctionsAreRefused) {
  Start();
  EXPECT_EQ(Ask(1, 2, {0x08, 0x00, 0x00, 0xA5, 0x37}), (Bytes{0x08, 0x00, 0x00, 0xA5, 0x37}));
  EXPECT_EQ(Ask(2, 2, {0x08, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04}),
            (Bytes{0x08, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04}));
  EXPECT_EQ(Ask(3, 2, {0x08, 0x00, 0x01, 0x00, 0x00}), (Bytes{0x88, 0x01}));  // restart comms
  EXPECT_EQ(Ask(4, 2, {0x08, 0x00, 0x00, 0x12}), (Bytes{0x88, 0x03}));        // half a register
}

TEST_F(StageTcpFramingTest, InjectedException04BurstsThenTheDriveAnswers) {
  Start();
  control_.set_modbus({.exception_code = 4, .exception_count = 2});
  EXPECT_EQ(Ask(1, 1, kReadStatus), (Bytes{0x83, 0x04}));
  EXPECT_EQ(Ask(2, 1, kReadStatus), (Bytes{0x83, 0x04}));
  EXPECT_EQ(Ask(3, 1, kReadStatus)[0], 0x03);
  EXPECT_EQ(control_.modbus().exception_count, 0);
}

// The control unit's outage (register 28): at the next axis request that connection closes and
// the port refuses connections for the outage's length, while a connection that only talks to
// the control unit stays served; then the same port accepts and the drives answer again.
TEST_F(StageTcpFramingTest, AnOutageRefusesConnectionsThenTheSamePortAnswersAgain) {
  Start();
  RawModbusClient control_link(stage_->tcp_port());
  ASSERT_TRUE(control_link.ok());
  // Register 28 = 600 ms, through the control unit as a test or an operator sets it.
  EXPECT_EQ(Ask(1, 100, {0x06, 0x00, 0x1C, 0x02, 0x58}), (Bytes{0x06, 0x00, 0x1C, 0x02, 0x58}));
  EXPECT_EQ(control_.modbus().outage_ms, 600);

  const auto began = SteadyClock::now();
  ASSERT_TRUE(client_->Send(Adu(2, 1, kReadStatus)));
  EXPECT_TRUE(client_->ReadAdu().empty());
  EXPECT_TRUE(client_->closed());
  EXPECT_EQ(control_.modbus().outage_ms, 0);  // fired
  EXPECT_FALSE(RawModbusClient(stage_->tcp_port()).ok()) << "a connection was accepted";

  // The control unit still answers on a connection opened before.
  ASSERT_TRUE(control_link.Send(Adu(3, 100, {0x03, 0x00, 0x1C, 0x00, 0x01})));
  EXPECT_EQ(PduOf(control_link.ReadAdu()), (Bytes{0x03, 0x02, 0x00, 0x00}));
  // ... but an axis request on it is dropped with its connection while the outage lasts.
  ASSERT_TRUE(control_link.Send(Adu(4, 2, kReadStatus)));
  EXPECT_TRUE(control_link.ReadAdu().empty());
  EXPECT_TRUE(control_link.closed());

  const auto give_up = SteadyClock::now() + std::chrono::seconds(5);
  do {
    client_ = std::make_unique<RawModbusClient>(stage_->tcp_port());
  } while (!client_->ok() && SteadyClock::now() < give_up);
  ASSERT_TRUE(client_->ok()) << "the port did not accept connections again";
  EXPECT_GE(SteadyClock::now() - began, std::chrono::milliseconds(550));
  EXPECT_EQ(Ask(5, 1, kReadStatus), (Bytes{0x03, 4, 0x00, 0x00, 0x40, 0x20}));
}

// The control unit's word-order swap (register 27): the drives lay their registers in the other
// order until it is cleared, as after a change of the drive's parameter.
TEST_F(StageTcpFramingTest, TheControlUnitSwapsTheDrivesWordOrder) {
  Start();
  EXPECT_EQ(Ask(1, 1, kReadStatus), (Bytes{0x03, 4, 0x00, 0x00, 0x40, 0x20}));
  EXPECT_EQ(Ask(2, 100, {0x06, 0x00, 0x1B, 0x00, 0x01})[0], 0x06);
  EXPECT_EQ(Ask(3, 1, kReadStatus), (Bytes{0x03, 4, 0x40, 0x20, 0x00, 0x00}));
  EXPECT_EQ(Ask(4, 100, {0x06, 0x00, 0x1B, 0x00, 0x02}), (Bytes{0x86, 0x03}));  // a flag: 0 or 1
  EXPECT_EQ(Ask(5, 100, {0x06, 0x00, 0x1B, 0x00, 0x00})[0], 0x06);
  EXPECT_EQ(Ask(6, 1, kReadStatus), (Bytes{0x03, 4, 0x00, 0x00, 0x40, 0x20}));
}

TEST(StageRtuFraming, AnFc08DiagnosisIsOneEightByteFrame) {
  // slave 2, FC08, sub-function 0, data 0xA537, CRC: the AZ's diagnosis request on RS-485.
  const Bytes frame{0x02, 0x08, 0x00, 0x00, 0xA5, 0x37};
  EXPECT_EQ(RtuRequestLength(frame), 8);
}

TEST(StageFunctionCodes, ProfilesAndListsParse) {
  std::string error;
  EXPECT_EQ(ParseFunctionCodes("az", &error), (FunctionCodes{3, 6, 8, 16}));
  EXPECT_EQ(ParseFunctionCodes("leadshine", &error), (FunctionCodes{3, 6, 16}));
  EXPECT_EQ(ParseFunctionCodes("moons", &error), (FunctionCodes{3, 4, 6, 16}));
  EXPECT_EQ(ParseFunctionCodes("16, 3,6", &error), (FunctionCodes{3, 6, 16}));
  EXPECT_FALSE(ParseFunctionCodes("3,5", &error).has_value());
  EXPECT_NE(error.find("'5'"), std::string::npos) << error;
  EXPECT_FALSE(ParseFunctionCodes("", &error).has_value());
  EXPECT_EQ(DescribeFunctionCodes({3, 6, 8, 16}), "03, 06, 08, 16");
}

}  // namespace
}  // namespace brdf::sim
