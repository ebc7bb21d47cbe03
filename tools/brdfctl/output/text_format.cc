#include "tools/brdfctl/output/text_format.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace brdf::ctl {

std::string ShortEnumName(std::string_view full_name, std::string_view prefix) {
  std::string_view rest = full_name;
  if (rest.substr(0, prefix.size()) == prefix) rest.remove_prefix(prefix.size());
  std::string out(rest);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out.empty() ? "unspecified" : out;
}

std::string StateName(v1::SessionState state) {
  return ShortEnumName(v1::SessionState_Name(state), "SESSION_STATE_");
}
std::string PromptKindName(v1::PromptKind kind) {
  return ShortEnumName(v1::PromptKind_Name(kind), "PROMPT_KIND_");
}
std::string StepKindName(v1::StepKind kind) {
  return ShortEnumName(v1::StepKind_Name(kind), "STEP_KIND_");
}
std::string ReadingKindName(v1::ReadingKind kind) {
  return ShortEnumName(v1::ReadingKind_Name(kind), "READING_KIND_");
}
std::string ConnectionStateName(v1::ConnectionState state) {
  return ShortEnumName(v1::ConnectionState_Name(state), "CONNECTION_STATE_");
}
std::string InterpolationStatusName(v1::InterpolationStatus status) {
  return ShortEnumName(v1::InterpolationStatus_Name(status), "INTERPOLATION_STATUS_");
}
std::string MethodName(v1::InterpolationMethod method) {
  return ShortEnumName(v1::InterpolationMethod_Name(method), "INTERPOLATION_METHOD_");
}
std::string QuantityName(v1::Quantity quantity) {
  return ShortEnumName(v1::Quantity_Name(quantity), "QUANTITY_");
}

bool ParseTrendName(std::string_view name, v1::InterpolationTrend* trend) {
  if (name == "none") {
    *trend = v1::INTERPOLATION_TREND_NONE;
  } else if (name == "bivariate") {
    *trend = v1::INTERPOLATION_TREND_BIVARIATE;
  } else {
    return false;
  }
  return true;
}

bool ParseCoordinatesName(std::string_view name, v1::InterpolationCoordinates* coordinates) {
  if (name == "incidence") {
    *coordinates = v1::INTERPOLATION_COORDINATES_INCIDENCE;
  } else if (name == "half-diff") {
    *coordinates = v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE;
  } else {
    return false;
  }
  return true;
}

std::string QuantityUnit(v1::Quantity quantity) {
  switch (quantity) {
    case v1::QUANTITY_RADIANCE:
      return "W·m⁻²·sr⁻¹·nm⁻¹";
    case v1::QUANTITY_REFLECTANCE:
      return "1";
    default:
      return "sr⁻¹";
  }
}

bool ParseStateName(std::string_view name, v1::SessionState* state) {
  std::string upper = "SESSION_STATE_";
  for (char c : name) upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return v1::SessionState_Parse(upper, state) && *state != v1::SESSION_STATE_UNSPECIFIED;
}

std::string Num(double value, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  std::string out = buf;
  if (out == "-0") out = "0";
  return out;
}

std::string Duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long long total = std::llround(seconds);
  if (total < 60) return std::to_string(total) + " s";
  char buf[32];
  const long long h = total / 3600;
  const long long m = (total % 3600) / 60;
  const long long s = total % 60;
  if (h > 0) {
    std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", h, m, s);
  } else {
    std::snprintf(buf, sizeof buf, "%lld:%02lld", m, s);
  }
  return buf;
}

std::string StageAngle(double degrees) {
  if (!std::isfinite(degrees)) return Num(degrees, 5);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f", std::round(degrees * 1000.0) / 1000.0);
  std::string out = buf;
  while (out.back() == '0') out.pop_back();
  if (out.back() == '.') out.pop_back();
  if (out == "-0") out = "0";
  return out;
}

std::string PoseText(const v1::Pose& pose) {
  return "α " + StageAngle(pose.alpha()) + "° β " + StageAngle(pose.beta()) + "° γ " +
         StageAngle(pose.gamma()) + "° δ " + StageAngle(pose.delta()) + "°";
}

std::string DirectionsText(const v1::Directions& d) {
  return "θi " + Num(d.theta_i(), 5) + "° φi " + Num(d.phi_i(), 5) + "° θo " + Num(d.theta_o(), 5) +
         "° φo " + Num(d.phi_o(), 5) + "°";
}

std::string IsoText(const v1::IsoDirection& d) {
  return "θi " + Num(d.theta_i(), 5) + "° θo " + Num(d.theta_o(), 5) + "° φ " + Num(d.phi(), 5) +
         "°";
}

std::string TimeText(const google::protobuf::Timestamp& time) {
  if (time.seconds() == 0 && time.nanos() == 0) return "-";
  const std::time_t t = static_cast<std::time_t>(time.seconds());
  std::tm utc{};
  gmtime_r(&t, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%SZ", &utc);
  return buf;
}

std::string LocalTimeText(const google::protobuf::Timestamp& time) {
  if (time.seconds() == 0 && time.nanos() == 0) return "-";
  const std::time_t t = static_cast<std::time_t>(time.seconds());
  std::tm local{};
  localtime_r(&t, &local);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S %z", &local);
  return buf;
}

}  // namespace brdf::ctl
