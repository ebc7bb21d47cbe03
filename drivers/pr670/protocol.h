// The PR-655/PR-670 remote-mode protocol as text (docs/pr670-protocol.md): the commands the driver
// sends and a parser for every reply it reads. Pure: no I/O, no clocks, no state.
//
// Every reply starts with the meter's result code ("00000" all well, "-0008" too dark); a
// command that fails is answered with that code alone. Parsers take the whole reply as it came
// off the wire (line ends included) and return the value or a kProtocolError naming the command,
// the line and what was expected there; a reply whose code is not 0 is a kDeviceError whose
// device_code() is the code, in the meter's words (DescribeResultCode).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::drivers::pr670 {

// ---- Commands (host → meter; the driver appends CR, except to PHOTO and Q) --------------------

inline constexpr std::string_view kRemoteModeCommand = "PHOTO";    // enter remote mode (no CR)
inline constexpr std::string_view kQuitCommand = "Q";              // leave remote mode (no CR)
inline constexpr std::string_view kMeasureSpectrumCommand = "M5";  // measure, send report 5
inline constexpr std::string_view kSpectrumCommand = "D5";         // report 5 of the last one
inline constexpr std::string_view kSerialNumberCommand = "D110";
inline constexpr std::string_view kModelCommand = "D111";   // instrument name ("PR-670")
inline constexpr std::string_view kLayoutCommand = "D120";  // points, bandwidth, first, last, step

// "SE0" (adaptive exposure) or "SE<ms>" (fixed). kInvalidArgument outside 0 or
// kMinExposureMs … kMaxExposureMs.
inline constexpr int kMinExposureMs = 3;
inline constexpr int kMaxExposureMs = 30000;
Result<std::string> ExposureCommand(int exposure_ms);
// "SN<n>": measurements averaged, 1 … 99.
Result<std::string> AveragesCommand(int averages);
// "SS1" (sync to the source's frequency, measured by the meter) or "SS0" (no sync).
std::string SyncCommand(bool on);

// ---- Result codes -----------------------------------------------------------------------------

// What a code means and how the quality policy (drivers/pr650/quality_codes.h) treats it: the
// policy's rules are keyed by the PR-650's quality codes, and each PR-670 code maps onto the one
// that asks for the same handling (too dark → 10 weak light: a longer exposure; sync failure →
// 07 unable to sync: sync off and measure again). Codes the sources do not name map to
// kUnknownPolicyCode, which the policy fails on.
struct ResultCodeInfo {
  int code;
  const char* meaning;  // "too dark"
  int policy_code;      // the PR-650 quality code with the same handling
};
inline constexpr int kUnknownPolicyCode = 999;
const ResultCodeInfo* FindResultCode(int code);
// "-8 (too dark)", "-3 (a code brdfd does not know; see the meter's manual)".
std::string DescribeResultCode(int code);
int PolicyCodeFor(int code);

// The result code a reply starts with: the leading (signed) integer of its first line, up to a
// comma or the line end ("00000,0,..." → 0, "-0008" → -8). kProtocolError when there is none.
Result<int> ParseResultCode(std::string_view reply, std::string_view command);

// Lines a report-5 reply has for `grid`: the header, then one per band.
inline std::size_t SpectrumReplyLines(const WavelengthGrid& grid) {
  return grid.count + 1;
}

// ---- Replies ----------------------------------------------------------------------------------

// "00000,<text>" (D110 serial number, D111 instrument name): the text, trimmed of blanks.
Result<std::string> ParseTextReply(std::string_view reply, std::string_view command);

// D120 "00000,201,0.00,380,780,2,256,7,247": points, bandwidth, first, last, step (then detector
// pixels, which are ignored).
Result<WavelengthGrid> ParseLayoutReply(std::string_view reply);

// The first line of report 5: "qqqqq,UUUU,peak,integrated,photon".
struct SpectrumHeader {
  int result_code = 0;
  int units_code = 0;            // 0 luminance (radiance), 1 illuminance (irradiance), ...
  double peak_nm = 0;            // peak wavelength
  double integrated = 0;         // integrated radiometric value
  double integrated_photon = 0;  // integrated photon radiometric value
};
Result<SpectrumHeader> ParseSpectrumHeader(std::string_view line, std::string_view command);

// Report 5: the header, then one "wl,value" line per band ("380,1.627e-03"), evenly spaced and
// increasing; `expected`, when given, must match them.
struct SpectrumReply {
  SpectrumHeader header;
  WavelengthGrid grid;
  std::vector<double> values;
};
Result<SpectrumReply> ParseSpectrumReply(std::string_view reply,
                                         std::optional<WavelengthGrid> expected,
                                         std::string_view command);

}  // namespace brdf::drivers::pr670
