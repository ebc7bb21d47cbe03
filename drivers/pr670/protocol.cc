#include "drivers/pr670/protocol.h"

#include <array>
#include <cmath>

#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers::pr670 {

namespace {

using pr650::ParseNumber;
using serial::Printable;
using serial::SplitReplyLines;

constexpr std::array<ResultCodeInfo, 4> kCodes = {{
    {0, "OK", 0},
    {-1, "light source sync failure", 7},
    {-8, "too dark", 10},
    {-10, "light source sync failure", 7},
}};

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(
        line.substr(start, comma == std::string_view::npos ? line.npos : comma - start));
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::optional<int> ParseInt(std::string_view field) {
  field = Trim(field);
  if (field.empty()) return std::nullopt;
  std::size_t i = field[0] == '-' || field[0] == '+' ? 1 : 0;
  if (i == field.size() || field.size() > 8) return std::nullopt;
  int value = 0;
  for (std::size_t k = i; k < field.size(); ++k) {
    if (field[k] < '0' || field[k] > '9') return std::nullopt;
    value = value * 10 + (field[k] - '0');
  }
  return field[0] == '-' ? -value : value;
}

Status BadLine(std::string_view command, std::size_t line_no, std::string_view line,
               std::string_view expected) {
  return ProtocolError("PR-670 reply to " + std::string(command) + ", line " +
                       std::to_string(line_no) + " \"" + Printable(line) + "\": expected " +
                       std::string(expected));
}

Status CodeNotZero(int code, std::string_view command) {
  return DeviceError(code, "PR-670 answered " + std::string(command) + " with result code " +
                               DescribeResultCode(code));
}

// The reply's lines, refusing an empty reply.
Result<std::vector<std::string>> Lines(std::string_view reply, std::string_view command) {
  std::vector<std::string> lines = SplitReplyLines(reply);
  if (lines.empty()) {
    return ProtocolError("PR-670 reply to " + std::string(command) + " is empty");
  }
  return lines;
}

}  // namespace

Result<std::string> ExposureCommand(int exposure_ms) {
  if (exposure_ms != 0 && (exposure_ms < kMinExposureMs || exposure_ms > kMaxExposureMs)) {
    return InvalidArgument("PR-670 exposure " + std::to_string(exposure_ms) +
                           " ms is out of range: use 0 (adaptive) or " +
                           std::to_string(kMinExposureMs) + "–" + std::to_string(kMaxExposureMs) +
                           " ms");
  }
  return "SE" + std::to_string(exposure_ms);
}

Result<std::string> AveragesCommand(int averages) {
  if (averages < 1 || averages > 99) {
    return InvalidArgument("PR-670 averages " + std::to_string(averages) +
                           " is out of range: use 1–99");
  }
  return "SN" + std::to_string(averages);
}

std::string SyncCommand(bool on) {
  return on ? "SS1" : "SS0";
}

const ResultCodeInfo* FindResultCode(int code) {
  for (const ResultCodeInfo& info : kCodes) {
    if (info.code == code) return &info;
  }
  return nullptr;
}

std::string DescribeResultCode(int code) {
  const ResultCodeInfo* info = FindResultCode(code);
  return std::to_string(code) + " (" +
         (info ? info->meaning : "a code brdfd does not know; see the meter's manual") + ")";
}

int PolicyCodeFor(int code) {
  const ResultCodeInfo* info = FindResultCode(code);
  return info ? info->policy_code : kUnknownPolicyCode;
}

Result<int> ParseResultCode(std::string_view reply, std::string_view command) {
  BRDF_ASSIGN_OR_RETURN(const std::vector<std::string> lines, Lines(reply, command));
  const std::string_view first = lines.front();
  const std::optional<int> code = ParseInt(first.substr(0, first.find(',')));
  if (!code) return BadLine(command, 1, first, "a result code (\"00000\", \"-0008\")");
  return *code;
}

Result<std::string> ParseTextReply(std::string_view reply, std::string_view command) {
  BRDF_ASSIGN_OR_RETURN(const int code, ParseResultCode(reply, command));
  if (code != 0) return CodeNotZero(code, command);
  const std::string first = SplitReplyLines(reply).front();
  const std::size_t comma = first.find(',');
  const std::string_view text = comma == std::string::npos
                                    ? std::string_view()
                                    : Trim(std::string_view(first).substr(comma + 1));
  if (text.empty()) return BadLine(command, 1, first, "\"00000,<text>\"");
  return std::string(text);
}

Result<WavelengthGrid> ParseLayoutReply(std::string_view reply) {
  constexpr std::string_view kCommand = kLayoutCommand;
  BRDF_ASSIGN_OR_RETURN(const int code, ParseResultCode(reply, kCommand));
  if (code != 0) return CodeNotZero(code, kCommand);
  const std::string first = SplitReplyLines(reply).front();
  const std::vector<std::string_view> f = SplitFields(first);
  const std::optional<int> points = f.size() >= 6 ? ParseInt(f[1]) : std::nullopt;
  const std::optional<double> start = f.size() >= 6 ? ParseNumber(f[3]) : std::nullopt;
  const std::optional<double> last = f.size() >= 6 ? ParseNumber(f[4]) : std::nullopt;
  const std::optional<double> step = f.size() >= 6 ? ParseNumber(f[5]) : std::nullopt;
  if (!points || !start || !last || !step || *points < 2 || *points > 10000 || *step <= 0 ||
      std::abs(*start + *step * (*points - 1) - *last) > *step / 2) {
    return BadLine(kCommand, 1, first,
                   "\"00000,points,bandwidth,first,last,step,...\" with first + step × (points "
                   "− 1) = last");
  }
  return WavelengthGrid{*start, *step, static_cast<std::size_t>(*points)};
}

Result<SpectrumHeader> ParseSpectrumHeader(std::string_view line, std::string_view command) {
  const std::vector<std::string_view> f = SplitFields(line);
  SpectrumHeader h;
  const std::optional<int> code = ParseInt(f[0]);
  if (!code) return BadLine(command, 1, line, "a result code (\"00000\")");
  h.result_code = *code;
  if (*code != 0) return h;  // an error code comes alone
  const std::optional<int> units = f.size() == 5 ? ParseInt(f[1]) : std::nullopt;
  const std::optional<double> peak = f.size() == 5 ? ParseNumber(f[2]) : std::nullopt;
  const std::optional<double> integrated = f.size() == 5 ? ParseNumber(f[3]) : std::nullopt;
  const std::optional<double> photon = f.size() == 5 ? ParseNumber(f[4]) : std::nullopt;
  if (!units || !peak || !integrated || !photon) {
    return BadLine(command, 1, line, "\"qqqqq,UUUU,peak,integrated,photon\"");
  }
  h.units_code = *units;
  h.peak_nm = *peak;
  h.integrated = *integrated;
  h.integrated_photon = *photon;
  return h;
}

Result<SpectrumReply> ParseSpectrumReply(std::string_view reply,
                                         std::optional<WavelengthGrid> expected,
                                         std::string_view command) {
  BRDF_ASSIGN_OR_RETURN(const std::vector<std::string> lines, Lines(reply, command));
  SpectrumReply out;
  BRDF_ASSIGN_OR_RETURN(out.header, ParseSpectrumHeader(lines.front(), command));
  if (out.header.result_code != 0) return CodeNotZero(out.header.result_code, command);
  if (lines.size() < 3) {
    return ProtocolError("PR-670 reply to " + std::string(command) + " has " +
                         std::to_string(lines.size()) +
                         " line(s): a report needs its header and "
                         "at least two bands");
  }
  std::vector<double> nm;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string_view> f = SplitFields(lines[i]);
    const std::optional<double> w = f.size() == 2 ? ParseNumber(f[0]) : std::nullopt;
    const std::optional<double> v = f.size() == 2 ? ParseNumber(f[1]) : std::nullopt;
    if (!w || !v) return BadLine(command, i + 1, lines[i], "\"wavelength,value\"");
    nm.push_back(*w);
    out.values.push_back(*v);
  }
  const double step = nm[1] - nm[0];
  for (std::size_t i = 1; i < nm.size(); ++i) {
    if (step <= 0 || std::abs(nm[i] - nm[0] - step * static_cast<double>(i)) > step / 4) {
      return BadLine(command, i + 1, lines[i], "evenly spaced, increasing wavelengths");
    }
  }
  out.grid = WavelengthGrid{nm[0], step, nm.size()};
  if (expected && !(*expected == out.grid)) {
    return ProtocolError("PR-670 reply to " + std::string(command) + " has " +
                         std::to_string(nm.size()) + " bands from " + std::to_string(nm[0]) +
                         " nm every " + std::to_string(step) + " nm, but the meter reported " +
                         std::to_string(expected->count) +
                         " bands (D120): the reply is "
                         "incomplete or garbled; measure again");
  }
  return out;
}

}  // namespace brdf::drivers::pr670
