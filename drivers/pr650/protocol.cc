#include "drivers/pr650/protocol.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <system_error>

#include "drivers/serial/reply_lines.h"

namespace brdf::drivers::pr650 {

using serial::Printable;
using serial::SplitReplyLines;

namespace {

bool IsDigit(char c) {
  return c >= '0' && c <= '9';
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      fields.push_back(line.substr(start));
      return fields;
    }
    fields.push_back(line.substr(start, comma - start));
    start = comma + 1;
  }
}

// A status or quality code: 1–3 digits (blank padding allowed), compared by value.
std::optional<int> ParseCode(std::string_view field) {
  field = Trim(field);
  if (field.empty() || field.size() > 3) return std::nullopt;
  int value = 0;
  for (char c : field) {
    if (!IsDigit(c)) return std::nullopt;
    value = value * 10 + (c - '0');
  }
  return value;
}

// "PR-650 reply to D120, line 1 "abc": expected ..."
Status LineError(std::string_view command, std::size_t line_number, std::string_view line,
                 std::string_view expected) {
  return ProtocolError("PR-650 reply to " + std::string(command) + ", line " +
                       std::to_string(line_number) + " \"" + Printable(line) + "\": expected " +
                       std::string(expected) +
                       "; the link may be noisy or the meter in another mode: retry, and "
                       "power-cycle the meter if it persists");
}

Status LineCountError(std::string_view command, std::size_t got, std::string_view expected,
                      std::string_view reply) {
  return ProtocolError("PR-650 reply to " + std::string(command) + " has " + std::to_string(got) +
                       " line(s), expected " + std::string(expected) + " (reply \"" +
                       Printable(reply) +
                       "\"); the link may be noisy or the meter in another mode: retry, and "
                       "power-cycle the meter if it persists");
}

// Rejects bytes the meter never sends in a line (control characters other than line ends, and
// anything outside 7-bit ASCII): line noise and a wrong baud rate show up as exactly these.
bool AllPrintable(std::string_view line) {
  for (char c : line) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u > 0x7e) return false;
  }
  return true;
}

// Splits and checks the common shape: exactly `want` non-empty printable lines.
Result<std::vector<std::string>> ExpectLines(std::string_view reply, std::string_view command,
                                             std::size_t want, std::string_view what) {
  std::vector<std::string> lines = SplitReplyLines(reply);
  if (lines.size() != want) return LineCountError(command, lines.size(), what, reply);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (!AllPrintable(lines[i])) {
      return LineError(command, i + 1, lines[i], std::string(what) + " in printable ASCII");
    }
  }
  return lines;
}

}  // namespace

// ---- Commands --------------------------------------------------------------------------------

std::optional<std::string> BacklightCommand(int level) {
  if (level < 0 || level > 3) return std::nullopt;
  return "B" + std::to_string(level);
}

Result<std::string> FormatSetupCommand(const SetupFields& f) {
  if (f.accessory < 1 || f.accessory > 12) {
    return InvalidArgument("PR-650 setup: accessory " + std::to_string(f.accessory) +
                           " is outside 01–12 (01 = the standard MS-75 lens)");
  }
  if (f.integration_ms != 0 && (f.integration_ms < 10 || f.integration_ms > 6000)) {
    return InvalidArgument("PR-650 setup: integration time " + std::to_string(f.integration_ms) +
                           " ms is outside 10–6000 ms (0 = adaptive)");
  }
  if (f.averages < 1 || f.averages > 99) {
    return InvalidArgument("PR-650 setup: " + std::to_string(f.averages) +
                           " averages is outside 1–99");
  }
  char text[64];
  std::snprintf(text, sizeof text, "S%02d,,,,%s,%d,%02d,%d", f.accessory, f.sync ? "1" : "",
                f.integration_ms, f.averages, f.si_units ? 1 : 0);
  return std::string(text);
}

// ---- Replies ---------------------------------------------------------------------------------

std::optional<double> ParseNumber(std::string_view field) {
  field = Trim(field);
  if (field.empty()) return std::nullopt;
  // Check the shape first: [sign] (digits [. digits] | . digits) [E [sign] digits]. from_chars
  // alone would also take "inf", "nan" and hex floats.
  std::size_t i = 0;
  bool negative = false;
  if (field[i] == '+' || field[i] == '-') {
    negative = field[i] == '-';
    ++i;
  }
  const std::size_t mantissa_start = i;
  std::size_t digits = 0;
  while (i < field.size() && IsDigit(field[i])) ++i, ++digits;
  if (i < field.size() && field[i] == '.') {
    ++i;
    while (i < field.size() && IsDigit(field[i])) ++i, ++digits;
  }
  if (digits == 0) return std::nullopt;
  const std::size_t mantissa_end = i;
  if (i < field.size() && (field[i] == 'E' || field[i] == 'e')) {
    ++i;
    if (i < field.size() && (field[i] == '+' || field[i] == '-')) ++i;
    std::size_t exponent_digits = 0;
    while (i < field.size() && IsDigit(field[i])) ++i, ++exponent_digits;
    if (exponent_digits == 0 || exponent_digits > 3) return std::nullopt;
  }
  if (i != field.size()) return std::nullopt;

  // from_chars takes neither a leading '+' nor a '+' in the exponent in every library version;
  // rebuild the number without them.
  std::string normalized;
  if (negative) normalized += '-';
  normalized.append(field.substr(mantissa_start, mantissa_end - mantissa_start));
  if (mantissa_end < field.size()) {
    normalized += 'e';
    std::string_view exponent = field.substr(mantissa_end + 1);
    if (exponent.front() == '+') exponent.remove_prefix(1);
    normalized.append(exponent);
  }
  double value = 0;
  const char* begin = normalized.data();
  const char* end = begin + normalized.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

bool IsNoMeasurementReply(std::string_view reply) {
  const std::vector<std::string> lines = SplitReplyLines(reply);
  return lines.size() == 1 && Trim(lines.front()) == "-1";
}

Result<int> ParseStatusReply(std::string_view reply, std::string_view command) {
  BRDF_ASSIGN_OR_RETURN(auto lines, ExpectLines(reply, command, 1, "one status line \"000\""));
  const std::string& line = lines.front();
  if (Trim(line) == "-1") return kNoMeasurementStatus;
  const std::optional<int> code = ParseCode(line);
  if (!code) return LineError(command, 1, line, "a 3-digit status such as \"000\"");
  return *code;
}

Result<int> ParseSetupReply(std::string_view reply) {
  BRDF_ASSIGN_OR_RETURN(auto lines, ExpectLines(reply, "S", 1, "one line \"pp\""));
  const std::string& line = lines.front();
  const std::optional<int> code = ParseCode(line);
  if (!code) {
    return LineError("S", 1, line,
                     "\"pp\": 00 accepted, 01–08 position of a bad field, 50 accessory error");
  }
  return *code;
}

std::string DescribeSetupReply(int code) {
  static const char* const kFieldNames[] = {"accessory 1 (lens)", "accessory 2", "accessory 3",
                                            "accessory 4",        "sync",        "integration time",
                                            "averages",           "units"};
  if (code == 0) return "setup accepted";
  if (code >= 1 && code <= 8) {
    return "field " + std::to_string(code) + " (" + kFieldNames[code - 1] + ") was rejected";
  }
  if (code == 50) return "accessory error: the accessory named in the setup is not fitted";
  return "unknown setup reply " + std::to_string(code);
}

Result<FlickerReply> ParseFlickerReply(std::string_view reply) {
  const std::vector<std::string> lines = SplitReplyLines(reply);
  if (lines.empty()) return LineCountError(kFlickerCommand, 0, "one line \"qq,freq\"", reply);
  const std::string& line = lines.front();
  if (!AllPrintable(line)) {
    return LineError(kFlickerCommand, 1, line, "\"qq,freq\" in printable ASCII");
  }
  const auto fields = SplitFields(line);
  if (fields.size() < 2) return LineError(kFlickerCommand, 1, line, "\"qq,freq\" (2 fields)");
  const auto code = ParseCode(fields[0]);
  if (!code) return LineError(kFlickerCommand, 1, line, "a quality code \"qq\" in field 1");
  // The frequency is the number the field starts with; a unit or other text after it is ignored.
  const std::string_view field = Trim(fields[1]);
  std::size_t end = 0;
  while (end < field.size() && (IsDigit(field[end]) || field[end] == '.' || field[end] == '+' ||
                                field[end] == '-' || field[end] == 'E' || field[end] == 'e')) {
    ++end;
  }
  std::optional<double> freq;
  // Shrink the prefix until it parses ("100.0E" of "100.0Ehz" is not a number, "100.0" is).
  for (std::size_t n = end; n > 0 && !freq; --n) freq = ParseNumber(field.substr(0, n));
  if (!freq) return LineError(kFlickerCommand, 1, line, "a frequency in Hz in field 2");
  FlickerReply out;
  out.quality_code = *code;
  out.frequency_hz = *freq;
  return out;
}

namespace {

// "qq,U,a,b,c": the shape shared by D1 and D2.
struct FiveFields {
  int quality_code = 0;
  int units_code = 0;
  double a = 0, b = 0, c = 0;
};

Result<FiveFields> ParseFiveFields(std::string_view reply, std::string_view command,
                                   std::string_view layout) {
  BRDF_ASSIGN_OR_RETURN(auto lines,
                        ExpectLines(reply, command, 1, "one line " + std::string(layout)));
  const std::string& line = lines.front();
  const auto fields = SplitFields(line);
  if (fields.size() != 5) return LineError(command, 1, line, std::string(layout) + " (5 fields)");
  const auto code = ParseCode(fields[0]);
  const auto units = ParseCode(fields[1]);
  if (!code) return LineError(command, 1, line, "a quality code \"qq\" in field 1");
  if (!units || Trim(fields[1]).size() != 1) {
    return LineError(command, 1, line, "a one-digit units code in field 2");
  }
  FiveFields out{*code, *units};
  double* const targets[] = {&out.a, &out.b, &out.c};
  for (int i = 0; i < 3; ++i) {
    const auto v = ParseNumber(fields[2 + i]);
    if (!v) {
      return LineError(command, 1, line,
                       "a number like 1.234E+01 in field " + std::to_string(3 + i));
    }
    *targets[i] = *v;
  }
  return out;
}

}  // namespace

Result<ColorimetryReply> ParseColorimetryReply(std::string_view reply) {
  BRDF_ASSIGN_OR_RETURN(
      auto f, ParseFiveFields(reply, kColorimetryCommand, "\"qq,U,Y.YYYEsee,.xxxx,.yyyy\""));
  return ColorimetryReply{f.quality_code, f.units_code, f.a, f.b, f.c};
}

Result<TristimulusReply> ParseTristimulusReply(std::string_view reply) {
  BRDF_ASSIGN_OR_RETURN(auto f, ParseFiveFields(reply, kTristimulusCommand, "\"qq,U,X,Y,Z\""));
  return TristimulusReply{f.quality_code, f.units_code, f.a, f.b, f.c};
}

Result<std::string> ParseSerialNumberReply(std::string_view reply) {
  BRDF_ASSIGN_OR_RETURN(
      auto lines, ExpectLines(reply, kSerialNumberCommand, 1, "one line with the serial number"));
  return std::string(Trim(lines.front()));
}

Result<SpectralLayout> ParseLayoutReply(std::string_view reply) {
  constexpr std::string_view kLayout =
      "\"pppp,bbb.b,ffff.,wwww.,iii.\" (points, bandwidth, first, last, step)";
  BRDF_ASSIGN_OR_RETURN(auto lines, ExpectLines(reply, kLayoutCommand, 1,
                                                std::string("one line ") + std::string(kLayout)));
  const std::string& line = lines.front();
  const auto fields = SplitFields(line);
  if (fields.size() != 5) return LineError(kLayoutCommand, 1, line, kLayout);

  SpectralLayout out;
  const std::string_view points = Trim(fields[0]);
  if (points.empty() || points.size() > 5) return LineError(kLayoutCommand, 1, line, kLayout);
  for (char c : points) {
    if (!IsDigit(c)) return LineError(kLayoutCommand, 1, line, kLayout);
    out.points = out.points * 10 + (c - '0');
  }
  double* const targets[] = {&out.bandwidth_nm, &out.first_nm, &out.last_nm, &out.step_nm};
  for (int i = 0; i < 4; ++i) {
    const auto v = ParseNumber(fields[1 + i]);
    if (!v) return LineError(kLayoutCommand, 1, line, kLayout);
    *targets[i] = *v;
  }
  if (out.points < 2 || out.step_nm <= 0 || out.bandwidth_nm <= 0 || out.first_nm <= 0) {
    return LineError(kLayoutCommand, 1, line,
                     "at least 2 points, a positive bandwidth, first wavelength and step");
  }
  const double implied_last = out.first_nm + out.step_nm * (out.points - 1);
  if (std::abs(implied_last - out.last_nm) > 0.01) {
    return LineError(kLayoutCommand, 1, line,
                     "first + (points - 1) * step to equal last (" + std::to_string(implied_last) +
                         " nm implied)");
  }
  return out;
}

Result<SpectrumHeader> ParseSpectrumHeader(std::string_view line, std::string_view command) {
  const auto fields = SplitFields(line);
  const std::optional<int> code = fields.size() == 2 ? ParseCode(fields[0]) : std::nullopt;
  const std::optional<int> units = fields.size() == 2 ? ParseCode(fields[1]) : std::nullopt;
  if (!code || !units || Trim(fields[1]).size() != 1) {
    return LineError(command, 1, line, "\"qq,U\" (quality code, one-digit units code)");
  }
  return SpectrumHeader{*code, *units};
}

Result<SpectrumReply> ParseSpectrumReply(std::string_view reply,
                                         std::optional<WavelengthGrid> expected,
                                         std::string_view command) {
  const std::vector<std::string> lines = SplitReplyLines(reply);
  if (lines.size() < 4) {
    return LineCountError(command, lines.size(),
                          "a header, the integrated intensity and at least 2 bands", reply);
  }
  if (expected && lines.size() != SpectrumReplyLines(*expected)) {
    return LineCountError(command, lines.size(),
                          std::to_string(SpectrumReplyLines(*expected)) + " (header, integrated, " +
                              std::to_string(expected->count) + " bands)",
                          reply);
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (!AllPrintable(lines[i])) {
      return LineError(command, i + 1, lines[i], "printable ASCII");
    }
  }

  SpectrumReply out;
  BRDF_ASSIGN_OR_RETURN(SpectrumHeader header, ParseSpectrumHeader(lines[0], command));
  out.quality_code = header.quality_code;
  out.units_code = header.units_code;

  const auto integrated = ParseNumber(lines[1]);
  if (!integrated) {
    return LineError(command, 2, lines[1], "the integrated intensity as a number like 1.234E+01");
  }
  out.integrated = *integrated;

  std::vector<double> wavelengths;
  for (std::size_t i = 2; i < lines.size(); ++i) {
    const auto fields = SplitFields(lines[i]);
    const std::optional<double> nm = fields.size() == 2 ? ParseNumber(fields[0]) : std::nullopt;
    const std::optional<double> value = fields.size() == 2 ? ParseNumber(fields[1]) : std::nullopt;
    if (!nm || !value) {
      return LineError(command, i + 1, lines[i],
                       "\"wwww.,r.rrrEsee\" (wavelength in nm, spectral value)");
    }
    wavelengths.push_back(*nm);
    out.values.push_back(*value);
  }

  const double step = wavelengths[1] - wavelengths[0];
  if (step <= 0) {
    return LineError(command, 4, lines[3], "wavelengths increasing from line 3 on");
  }
  for (std::size_t i = 0; i < wavelengths.size(); ++i) {
    const double want = wavelengths[0] + step * static_cast<double>(i);
    if (std::abs(wavelengths[i] - want) > 0.01) {
      return LineError(command, i + 3, lines[i + 2],
                       "evenly spaced wavelengths (" + std::to_string(want) + " nm here)");
    }
  }
  out.grid = WavelengthGrid{wavelengths[0], step, wavelengths.size()};
  if (expected && (std::abs(expected->start_nm - out.grid.start_nm) > 0.01 ||
                   std::abs(expected->step_nm - out.grid.step_nm) > 0.01)) {
    return ProtocolError(
        "PR-650 reply to " + std::string(command) + " covers " + std::to_string(out.grid.start_nm) +
        " nm every " + std::to_string(out.grid.step_nm) +
        " nm, but the meter's layout (D120) says " + std::to_string(expected->start_nm) +
        " nm every " + std::to_string(expected->step_nm) +
        " nm; re-identify the meter (D120) and retry");
  }
  return out;
}

}  // namespace brdf::drivers::pr650
