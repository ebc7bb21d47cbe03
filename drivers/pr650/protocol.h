// The PR-650 remote-mode protocol as text: the commands the driver sends and a parser for every
// reply it reads (see docs/pr650.md). Pure: no I/O, no clocks, no state, so it
// can be unit-tested line by line and fuzzed.
//
// Every parser takes the whole reply as it came off the wire (line ends included) and either
// returns the decoded value or a kProtocolError that names the command, the line number, the line
// itself (non-printable bytes escaped) and what was expected there.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"
#include "core/wavelength_grid.h"

namespace brdf::drivers::pr650 {

// ---- Commands (host → meter; the driver appends the line end) --------------------------------

inline constexpr std::string_view kMeasureCommand = "M0";   // measure and hold, reply 000
inline constexpr std::string_view kSpectrumCommand = "D5";  // spectrum of the last measurement
// Measure, then send the D5 report: one exchange per reading instead of two (M1…M6 are "measure,
// then send report n").
inline constexpr std::string_view kMeasureSpectrumCommand = "M5";
inline constexpr std::string_view kSerialNumberCommand = "D110";
inline constexpr std::string_view kLayoutCommand = "D120";     // spectral layout
inline constexpr std::string_view kFlickerCommand = "F";       // flicker frequency for sync
inline constexpr std::string_view kColorimetryCommand = "D1";  // Y, x, y
inline constexpr std::string_view kTristimulusCommand = "D2";  // X, Y, Z

// "B0" … "B3" (backlight off … max); also the usual first command, which enters remote mode.
// Returns std::nullopt for a level outside 0–3.
std::optional<std::string> BacklightCommand(int level);

// The fields of the S (setup) command that the driver uses. Fields not listed here (accessories
// 2–4) are sent empty, which means "the meter's default".
struct SetupFields {
  int accessory = 1;       // acc1: 01 = the standard MS-75 lens (01–12)
  bool sync = false;       // true: sync to the last F result ("1"); false: field left empty
  int integration_ms = 0;  // 0 = adaptive, else 10–6000 ms
  int averages = 1;        // 01–99
  bool si_units = true;    // "1" = SI, "0" = English
  friend bool operator==(const SetupFields&, const SetupFields&) = default;
};

// "S01,,,,,0,01,1" style. Checks the ranges first: kInvalidArgument names the bad field.
Result<std::string> FormatSetupCommand(const SetupFields& fields);

// ---- Replies ---------------------------------------------------------------------------------

// Parses one PR-650 number: "d.dddE±dd" (9 characters) is what the meter sends; a sign, other digit
// counts, a missing exponent and blank padding are accepted too. No inf/nan/hex.
std::optional<double> ParseNumber(std::string_view field);

// The status line "-1": the meter has no measurement to report (a report asked for before any
// measurement, or a measurement that gave no data). The open drivers read it as "no data".
inline constexpr int kNoMeasurementStatus = -1;

// True when `reply` is the single status line "-1" (blank padding and line ends allowed), the
// whole reply a meter sends instead of a report it cannot give.
bool IsNoMeasurementReply(std::string_view reply);

// The "000" reply to B0–B3 and M0, a 3-digit status whose numeric value is the quality code (0 =
// OK). Compared numerically ("0", "00" and "000" are all 0) so that "1" and "01" agree. Accepts 1–3
// digits, and "-1" (kNoMeasurementStatus). `command` only names the reply in error messages.
Result<int> ParseStatusReply(std::string_view reply, std::string_view command);

// The "pp" reply to S: 0 = accepted, 1–8 = position of the bad field, 50 = accessory error.
Result<int> ParseSetupReply(std::string_view reply);

// What a setup reply code means, for messages ("field 6 (integration time) is out of range").
std::string DescribeSetupReply(int code);

// The "qq,freq" reply to F. Text after the frequency (a unit, further fields, further lines) is
// ignored: the quality code and the number the frequency field starts with are what counts.
struct FlickerReply {
  int quality_code = 0;
  double frequency_hz = 0;
};
Result<FlickerReply> ParseFlickerReply(std::string_view reply);

// The "qq,U,Y.YYYEsee,.xxxx,.yyyy" reply to D1.
struct ColorimetryReply {
  int quality_code = 0;
  int units_code = 0;
  double luminance = 0;  // Y
  double x = 0;
  double y = 0;
};
Result<ColorimetryReply> ParseColorimetryReply(std::string_view reply);

// The "qq,U,X,Y,Z" reply to D2.
struct TristimulusReply {
  int quality_code = 0;
  int units_code = 0;
  double X = 0;
  double Y = 0;
  double Z = 0;
};
Result<TristimulusReply> ParseTristimulusReply(std::string_view reply);

// The D110 reply: the serial number (up to 8 characters, maybe blank-padded), trimmed.
Result<std::string> ParseSerialNumberReply(std::string_view reply);

// The D120 reply "pppp,bbb.b,ffff.,wwww.,iii.": points, bandwidth, first, last, step.
struct SpectralLayout {
  int points = 0;
  double bandwidth_nm = 0;
  double first_nm = 0;
  double last_nm = 0;
  double step_nm = 0;
  WavelengthGrid grid() const { return {first_nm, step_nm, static_cast<std::size_t>(points)}; }
};
Result<SpectralLayout> ParseLayoutReply(std::string_view reply);

// The first line of a D5 (or M5) report, "qq,U": the measurement's quality code and the units
// code. Read on its own so a driver can act on the quality before the bands have all arrived.
struct SpectrumHeader {
  int quality_code = 0;
  int units_code = 0;
};
Result<SpectrumHeader> ParseSpectrumHeader(std::string_view line,
                                           std::string_view command = kSpectrumCommand);

// The D5 report: "qq,U", the integrated intensity, then one "wwww.,r.rrrEsee" line per band.
// The bands must be evenly spaced and increasing; `expected`, when given, must match them.
// `command` (D5 or M5) only names the reply in error messages.
struct SpectrumReply {
  int quality_code = 0;
  int units_code = 0;
  double integrated = 0;
  WavelengthGrid grid;
  std::vector<double> values;  // one per band of `grid`
};
Result<SpectrumReply> ParseSpectrumReply(std::string_view reply,
                                         std::optional<WavelengthGrid> expected = std::nullopt,
                                         std::string_view command = kSpectrumCommand);

// Lines in a D5 report for `grid`: header, integrated intensity, one per band (the framing layer
// waits for this many).
inline std::size_t SpectrumReplyLines(const WavelengthGrid& grid) {
  return grid.count + 2;
}

}  // namespace brdf::drivers::pr650
