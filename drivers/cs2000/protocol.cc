#include "drivers/cs2000/protocol.h"

#include <array>
#include <cmath>
#include <cstdio>

#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_lines.h"

namespace brdf::drivers::cs2000 {

namespace {

using pr650::ParseNumber;
using serial::Printable;

constexpr std::array<ErrorCodeInfo, 13> kCodes = {{
    {0, "invalid command string or number of parameters", kFailPolicyCode},
    {2, "measurement error", 29},
    {5, "no user calibration values", kFailPolicyCode},
    {10, "over measurement range", 19},
    {17, "parameter error", kFailPolicyCode},
    {20, "no data", kFailPolicyCode},
    {51, "CCD Peltier abnormality", kFailPolicyCode},
    {52, "temperature count abnormality", kFailPolicyCode},
    {71, "outside synchronization signal range", 7},
    {81, "shutter operation abnormality", kFailPolicyCode},
    {82, "internal ND filter operation malfunction", kFailPolicyCode},
    {83, "measurement angle abnormality", kFailPolicyCode},
    {99, "program abnormality", kFailPolicyCode},
}};

std::string_view Strip(std::string_view s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == ' ')) {
    s.remove_suffix(1);
  }
  while (!s.empty() && (s.front() == '\r' || s.front() == '\n' || s.front() == ' ')) {
    s.remove_prefix(1);
  }
  return s;
}

Status Bad(std::string_view command, std::string_view line, std::string_view expected) {
  return ProtocolError("CS-2000 reply to " + std::string(command) + " \"" + Printable(line) +
                       "\": expected " + std::string(expected));
}

bool Digits(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

std::string SpectralBlockCommand(int block) {
  return "MEDR,1,0," + std::to_string(block);
}

Result<std::string> SpeedCommand(int integration_ms, NdFilter nd) {
  const int nd_code = static_cast<int>(nd);
  if (integration_ms == 0) return "SPMS,0," + std::to_string(nd_code);
  if (integration_ms < kMinIntegrationMs || integration_ms > kMaxIntegrationMs) {
    return InvalidArgument("CS-2000 integration " + std::to_string(integration_ms) +
                           " ms is out of range: use 0 (the meter chooses) or " +
                           std::to_string(kMinIntegrationMs) + "–" +
                           std::to_string(kMaxIntegrationMs) + " ms");
  }
  char micros[16];
  std::snprintf(micros, sizeof micros, "%09lld", static_cast<long long>(integration_ms) * 1000);
  return "SPMS,3," + std::string(micros) + "," + std::to_string(nd_code);
}

Result<std::string> SyncCommand(bool on, double frequency_hz) {
  if (!on) return std::string("SCMS,0");
  if (!(frequency_hz >= 20 && frequency_hz <= 200)) {
    return InvalidArgument("CS-2000 sync frequency " + std::to_string(frequency_hz) +
                           " Hz is out of range: use 20–200 Hz");
  }
  return "SCMS,1," + std::to_string(static_cast<long>(std::lround(frequency_hz * 100)));
}

const ErrorCodeInfo* FindErrorCode(int code) {
  for (const ErrorCodeInfo& info : kCodes) {
    if (info.code == code) return &info;
  }
  return nullptr;
}

std::string DescribeErrorCode(int code) {
  char name[8];
  std::snprintf(name, sizeof name, "ER%02d", code);
  const ErrorCodeInfo* info = FindErrorCode(code);
  return std::string(name) + " (" +
         (info ? info->meaning : "a code brdfd does not know; see the meter's manual") + ")";
}

int PolicyCodeFor(int code) {
  const ErrorCodeInfo* info = FindErrorCode(code);
  return info ? info->policy_code : kFailPolicyCode;
}

Result<Reply> ParseReply(std::string_view reply, std::string_view command) {
  const std::string_view line = Strip(reply);
  if (line.find_first_of("\r\n") != std::string_view::npos) {
    return Bad(command, line, "one line");
  }
  Reply out;
  std::size_t start = 0;
  std::vector<std::string> fields;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.emplace_back(line.substr(start, comma == line.npos ? line.npos : comma - start));
    if (comma == line.npos) break;
    start = comma + 1;
  }
  const std::string& check = fields.front();
  if (check.size() != 4 || !Digits(std::string_view(check).substr(2)) ||
      (check.compare(0, 2, "OK") != 0 && check.compare(0, 2, "ER") != 0)) {
    return Bad(command, line, "a check code OK00 or ERxx first");
  }
  out.ok = check.compare(0, 2, "OK") == 0;
  out.code = std::stoi(check.substr(2));
  out.fields.assign(fields.begin() + 1, fields.end());
  return out;
}

Result<Reply> ParseOkReply(std::string_view reply, std::string_view command) {
  BRDF_ASSIGN_OR_RETURN(Reply parsed, ParseReply(reply, command));
  if (!parsed.ok) {
    return DeviceError(parsed.code, "CS-2000 answered " + std::string(command) + " with " +
                                        DescribeErrorCode(parsed.code));
  }
  return parsed;
}

Result<Identity> ParseIdentityReply(std::string_view reply) {
  BRDF_ASSIGN_OR_RETURN(const Reply r, ParseOkReply(reply, kIdentityCommand));
  if (r.fields.size() < 3 || r.fields[2].empty()) {
    return Bad(kIdentityCommand, Strip(reply), "\"OK00,<product>,<variation>,<serial>\"");
  }
  Identity id;
  id.model = r.fields[1] == "1" ? "CS-2000" : r.fields[1] == "2" ? "CS-2000A" : r.fields[0];
  id.serial_number = r.fields[2];
  return id;
}

Result<int> ParseMeasuringTime(std::string_view reply) {
  BRDF_ASSIGN_OR_RETURN(const Reply r, ParseOkReply(reply, kMeasureCommand));
  if (r.fields.size() != 1 || !Digits(r.fields[0]) || r.fields[0].size() > 6) {
    return Bad(kMeasureCommand, Strip(reply), "\"OK00,<measuring time in s>\"");
  }
  return std::stoi(r.fields[0]);
}

Result<std::vector<double>> ParseSpectralBlock(std::string_view reply, int block) {
  const std::string command = SpectralBlockCommand(block);
  BRDF_ASSIGN_OR_RETURN(const Reply r, ParseOkReply(reply, command));
  if (r.fields.size() != BlockValues(block)) {
    return ProtocolError("CS-2000 reply to " + command + " holds " +
                         std::to_string(r.fields.size()) + " values, not " +
                         std::to_string(BlockValues(block)) +
                         ": the reply is incomplete or garbled; measure again");
  }
  std::vector<double> values;
  values.reserve(r.fields.size());
  for (std::size_t i = 0; i < r.fields.size(); ++i) {
    const std::optional<double> v = ParseNumber(r.fields[i]);
    if (!v) {
      return ProtocolError("CS-2000 reply to " + command + ": value " + std::to_string(i + 1) +
                           " \"" + Printable(r.fields[i]) + "\" is not a number");
    }
    values.push_back(*v);
  }
  return values;
}

}  // namespace brdf::drivers::cs2000
