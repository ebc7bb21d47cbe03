// The Konica Minolta CS-2000 / CS-2000A / CS-3000 remote protocol as text
// (docs/cs2000-protocol.md): the commands the driver sends and a parser for every reply it reads.
// Pure: no I/O, no clocks, no state.
//
// A command is a keyword and comma-separated parameters ended by LF ("MEDR,1,0,1"); every reply
// is one line that starts with a check code, OK00 or ERxx, then the data, comma-separated.
// Parsers take the reply as it came off the wire and return the data or a kProtocolError naming
// the command and the line; an ERxx reply is a kDeviceError whose device_code() is xx, in the
// meter's words (DescribeErrorCode).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::drivers::cs2000 {

// ---- Commands (host → meter; the driver appends LF) --------------------------------------------

inline constexpr std::string_view kRemoteOnCommand = "RMTS,1";
inline constexpr std::string_view kRemoteOffCommand = "RMTS,0";
inline constexpr std::string_view kIdentityCommand = "IDDR";
inline constexpr std::string_view kMeasureCommand = "MEAS,1";
inline constexpr std::string_view kConditionsCommand = "MEDR,0,0,1";  // last measurement's setup

// "MEDR,1,0,<block>": spectral data block 1–4 in ASCII (380–479, 480–579, 580–679, 680–780 nm).
std::string SpectralBlockCommand(int block);
inline constexpr int kBlocks = 4;

// The CS-2000's grid: 380–780 nm every 1 nm, 401 values.
inline WavelengthGrid Grid() {
  return {380, 1, 401};
}
// Values in block `block` (1–4): 100, 100, 100, 101.
inline std::size_t BlockValues(int block) {
  return block == kBlocks ? 101 : 100;
}

// Internal ND filter: off (0), on (1), automatic (2).
enum class NdFilter { kOff = 0, kOn = 1, kAuto = 2 };

// "SPMS,0,<nd>" (normal speed: the meter chooses the integration) for integration_ms 0, else
// "SPMS,3,<µs as 9 digits>,<nd>" (manual integration). kInvalidArgument outside
// kMinIntegrationMs … kMaxIntegrationMs.
inline constexpr int kMinIntegrationMs = 5;
inline constexpr int kMaxIntegrationMs = 120000;
Result<std::string> SpeedCommand(int integration_ms, NdFilter nd);
// "SCMS,0" (no sync) or "SCMS,1,<hz × 100>" (internal sync at the lamp's frequency, 20–200 Hz).
Result<std::string> SyncCommand(bool on, double frequency_hz);

// ---- Check codes --------------------------------------------------------------------------------

// What an ERxx means and how the quality policy (drivers/pr650/quality_codes.h, keyed by the
// PR-650's codes) treats it: ER10 (over the measurement range) as 19 (overload: a shorter
// integration), ER71 (outside the sync signal's range) as 07 (sync off, measure again), ER02
// (measurement error) as 29 (measure again); every other code fails.
struct ErrorCodeInfo {
  int code;
  const char* meaning;
  int policy_code;  // kFailPolicyCode: the policy fails on it
};
inline constexpr int kFailPolicyCode = 999;
const ErrorCodeInfo* FindErrorCode(int code);
std::string DescribeErrorCode(int code);  // "ER10 (over measurement range)"
int PolicyCodeFor(int code);              // of ERxx's xx (OK00 is the policy's 0)

// One reply: its check code (0 for OK00, xx for ERxx) and its data fields.
struct Reply {
  bool ok = false;
  int code = 0;
  std::vector<std::string> fields;
};
// Parses "OK00[,data...]" or "ERxx"; kProtocolError for anything else.
Result<Reply> ParseReply(std::string_view reply, std::string_view command);
// As ParseReply, with an ERxx turned into its kDeviceError.
Result<Reply> ParseOkReply(std::string_view reply, std::string_view command);

// ---- Replies ------------------------------------------------------------------------------------

// IDDR "OK00,<product>,<variation>,<serial>": the model (variation 1 CS-2000, 2 CS-2000A,
// otherwise the product name as given) and the serial number.
struct Identity {
  std::string model;
  std::string serial_number;
};
Result<Identity> ParseIdentityReply(std::string_view reply);

// MEAS,1's first reply "OK00,<seconds>": the measuring time the meter announces.
Result<int> ParseMeasuringTime(std::string_view reply);

// MEDR,1,0,<block>: the block's values (BlockValues(block) of them).
Result<std::vector<double>> ParseSpectralBlock(std::string_view reply, int block);

}  // namespace brdf::drivers::cs2000
