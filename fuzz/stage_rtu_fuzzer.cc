// Fuzz target: the simulator's side of the stage bus, which the driver's tests and the fault
// campaign trust: the RTU frame splitter and CRC (tools/brdf-sim/stage/rtu_frame.h), the PDU
// layer (tools/brdf-sim/stage/pdu.h) and the simulated drives and control unit behind it
// (tools/brdf-sim/stage/sim_axis.h, tools/brdf-sim/stage/control_unit.h), on simulated time. Then
// the driver's codec reads the drive's status and position back over the same PDU layer and must
// agree with the drive.
//
// Input: chunks of [control] [length] [bytes...]; control's low 5 bits are the pause before the
// chunk in 10 ms units, bit 5 asks the splitter to expire stale bytes first, bit 6 appends a
// valid CRC to the chunk (so the fuzzer reaches the PDU layer without solving CRC-16), bit 7
// waits a simulated second more (moves finish).
//
// Promises checked: every frame the splitter yields carries a valid CRC and the length its
// function code implies; after draining, fewer bytes stay buffered than the longest frame; every
// answer is a well-formed response or exception for its request; the codec's reading of the
// drive matches the drive's own state.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "drivers/stage/modbus_codec.h"
#include "drivers/stage/register_profile.h"
#include "fuzz/fuzz_check.h"
#include "tools/brdf-sim/stage/control_unit.h"
#include "tools/brdf-sim/stage/pdu.h"
#include "tools/brdf-sim/stage/rtu_frame.h"
#include "tools/brdf-sim/stage/sim_axis.h"

namespace brdf::fuzz {
namespace {

using namespace brdf::sim;

constexpr std::size_t kLongestRequest = 9 + 255;

std::string Hex(std::span<const std::uint8_t> bytes) {
  std::string out;
  char b[4];
  for (std::uint8_t v : bytes) {
    std::snprintf(b, sizeof b, "%02X ", v);
    out += b;
  }
  return out;
}

void CheckResponse(std::span<const std::uint8_t> request, const std::vector<std::uint8_t>& resp) {
  const std::string where = "request " + Hex(request) + "-> response " + Hex(resp);
  BRDF_FUZZ_CHECK(!resp.empty(), "empty response PDU: " + where);
  const std::uint8_t fc = request.empty() ? 0 : request[0];
  if ((resp[0] & 0x80) != 0) {
    BRDF_FUZZ_CHECK(resp.size() == 2 && resp[0] == (fc | 0x80), "malformed exception: " + where);
    const std::uint8_t code = resp[1];
    BRDF_FUZZ_CHECK(code == 1 || code == 2 || code == 3 || code == 4 || code == 6 || code == 0x0B,
                    "unexpected exception code: " + where);
    return;
  }
  BRDF_FUZZ_CHECK(resp[0] == fc, "response for another function: " + where);
  if (fc == modbus::kReadHoldingRegisters || fc == modbus::kReadInputRegisters) {
    const std::size_t count = (std::size_t{request[3]} << 8) | request[4];
    BRDF_FUZZ_CHECK(resp.size() == 2 + 2 * count && resp[1] == 2 * count,
                    "read response of the wrong length: " + where);
  } else if (fc == modbus::kWriteSingleRegister) {
    BRDF_FUZZ_CHECK(std::equal(request.begin(), request.end(), resp.begin(), resp.end()),
                    "FC06 not echoed: " + where);
  } else if (fc == modbus::kWriteMultipleRegisters) {
    BRDF_FUZZ_CHECK(
        resp.size() == 5 && std::equal(resp.begin() + 1, resp.end(), request.begin() + 1),
        "FC16 answer does not repeat address and count: " + where);
  } else if (fc == modbus::kDiagnostics) {
    // FC08 sub-function 0 (return query data) echoes the request; no other sub-function answers.
    BRDF_FUZZ_CHECK(std::equal(request.begin(), request.end(), resp.begin(), resp.end()),
                    "FC08 not echoed: " + where);
  } else {
    InvariantFailed("success", __FILE__, __LINE__, "unknown function answered: " + where);
  }
}

// Reads `count` registers at `address` of `unit` the way the driver does (FC03).
std::vector<std::uint16_t> ReadOverPdu(RegisterUnit& unit, std::uint16_t address,
                                       std::uint16_t count) {
  const std::uint8_t req[] = {
      modbus::kReadHoldingRegisters, static_cast<std::uint8_t>(address >> 8),
      static_cast<std::uint8_t>(address), 0, static_cast<std::uint8_t>(count)};
  const std::vector<std::uint8_t> resp = ServePdu(req, unit);
  CheckResponse(req, resp);
  std::vector<std::uint16_t> regs;
  if ((resp[0] & 0x80) != 0) return regs;
  for (std::size_t i = 0; i < count; ++i) {
    regs.push_back(static_cast<std::uint16_t>((resp[2 + 2 * i] << 8) | resp[3 + 2 * i]));
  }
  return regs;
}

}  // namespace

int FuzzStageRtu(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  double now_s = 0;
  SimControl control;
  SimAxisConfig alpha_config;
  alpha_config.unit_id = 1;
  alpha_config.min_deg = 0;
  alpha_config.max_deg = 90;
  SimAxisConfig beta_config;
  beta_config.unit_id = 2;
  SimAxis alpha(alpha_config, control, [&] { return now_s; });
  SimAxis beta(beta_config, control, [&] { return now_s; });
  StageControlUnit control_unit(control, {});

  using Clock = RtuFrameSplitter::TimePoint::clock;
  const RtuFrameSplitter::TimePoint t0{};
  RtuFrameSplitter splitter;
  while (!in.empty()) {
    const std::uint8_t ctl = in.Byte();
    const std::size_t length = in.Byte();
    now_s += 0.010 * (ctl & 0x1f) + ((ctl & 0x80) != 0 ? 1.0 : 0.0);
    const auto now =
        t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(now_s));
    const std::string_view chunk = in.Take(length);
    std::vector<std::uint8_t> bytes(chunk.begin(), chunk.end());
    if ((ctl & 0x40) != 0) AppendCrc(bytes);
    if ((ctl & 0x20) != 0) splitter.Expire(now);
    splitter.Feed(bytes, now);

    while (auto frame = splitter.Next()) {
      BRDF_FUZZ_CHECK(frame->size() >= 2, "a frame without a function code");
      std::vector<std::uint8_t> wire = *frame;
      AppendCrc(wire);
      BRDF_FUZZ_CHECK(ModbusCrc16(wire) == 0, "a frame with a bad CRC: " + Hex(wire));
      BRDF_FUZZ_CHECK(RtuRequestLength(wire) == static_cast<int>(wire.size()),
                      "a frame whose length does not match its function: " + Hex(wire));
      RegisterUnit* unit = nullptr;
      switch ((*frame)[0]) {
        case 1:
          unit = &alpha;
          break;
        case 2:
          unit = &beta;
          break;
        case 100:
          unit = &control_unit;
          break;
        default:
          break;  // not on this line: no answer
      }
      if (unit == nullptr) continue;
      const std::span<const std::uint8_t> pdu = std::span(*frame).subspan(1);
      CheckResponse(pdu, ServePdu(pdu, *unit));
    }
    BRDF_FUZZ_CHECK(splitter.buffered() < kLongestRequest,
                    "the splitter holds " + std::to_string(splitter.buffered()) + " bytes");
    BRDF_FUZZ_CHECK(splitter.crc_errors() >= 0 && splitter.dropped_bytes() >= 0,
                    "counters overflowed");
  }

  // The driver's view of the alpha drive (AZ map) must match the drive's own state, read in the
  // word order the drive lays values in now (the control unit's register 27 swaps it, as a lab
  // may set a drive to the other order than the profile's).
  auto profile = drivers::stage::RegisterProfile::AzDefault();
  if (control.modbus().swap_word_order) {
    profile.word_order = profile.word_order == drivers::stage::WordOrder::kHighFirst
                             ? drivers::stage::WordOrder::kLowFirst
                             : drivers::stage::WordOrder::kHighFirst;
  }
  const auto status =
      ReadOverPdu(alpha, profile.status.address, static_cast<std::uint16_t>(profile.status.words));
  const auto position = ReadOverPdu(alpha, profile.feedback_position.address,
                                    static_cast<std::uint16_t>(profile.feedback_position.words));
  const SimAxisSnapshot snap = alpha.Snapshot();
  if (!status.empty() && !position.empty() && !snap.moving) {
    const auto flags = drivers::stage::DecodeStatus(
        drivers::stage::DecodeUnsigned(status, profile.word_order), profile.status_bits);
    BRDF_FUZZ_CHECK(flags.alarm == snap.alarm && flags.moving == snap.moving &&
                        flags.in_position == snap.in_position,
                    "decoded status flags differ from the drive's state");
    BRDF_FUZZ_CHECK(
        drivers::stage::DecodeSigned(position, profile.word_order) == snap.position_counts,
        "decoded feedback position differs from the drive's");
  }
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzStageRtu)
