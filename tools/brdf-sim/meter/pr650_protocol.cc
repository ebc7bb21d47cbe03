#include "tools/brdf-sim/meter/pr650_protocol.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

namespace brdf::sim {

namespace {

// A field of digits only (1–4 of them), as a number; std::nullopt otherwise.
std::optional<int> Digits(std::string_view field) {
  if (field.empty() || field.size() > 4) return std::nullopt;
  int value = 0;
  for (char c : field) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
  }
  return value;
}

}  // namespace

std::string FormatPr650Number(double value) {
  if (!std::isfinite(value) || std::abs(value) < 1e-99) return "0.000E+00";
  if (std::abs(value) >= 9.9995e99) return value < 0 ? "-9.999E+99" : "9.999E+99";
  char text[32];
  std::snprintf(text, sizeof text, "%.3E", value);
  std::string out = text;
  // Rounding can carry a value just under 1e-99 to "1.000E-100"; the meter has two exponent digits.
  if (out.size() > (value < 0 ? 10u : 9u)) return "0.000E+00";
  return out;
}

std::vector<std::string> Pr650SpectrumLines(int quality_code, int units_code, double integrated,
                                            const std::vector<double>& radiance) {
  std::vector<std::string> lines;
  lines.reserve(kPr650Bands + 2);
  char text[48];
  std::snprintf(text, sizeof text, "%02d,%d", quality_code, units_code);
  lines.emplace_back(text);
  lines.push_back(FormatPr650Number(integrated));
  for (int i = 0; i < kPr650Bands; ++i) {
    const double v =
        i < static_cast<int>(radiance.size()) ? radiance[static_cast<std::size_t>(i)] : 0.0;
    std::snprintf(text, sizeof text, "%04d.,%s", kPr650FirstNm + kPr650StepNm * i,
                  FormatPr650Number(v).c_str());
    lines.emplace_back(text);
  }
  return lines;
}

namespace {

// One lobe of the Wyman–Sloan–Shirley fit: a Gaussian with different widths either side of μ.
double Lobe(double nm, double mu, double sigma_below, double sigma_above) {
  const double t = (nm - mu) / (nm < mu ? sigma_below : sigma_above);
  return std::exp(-0.5 * t * t);
}

// "qq,U," for the colorimetric reports.
std::string ReportHead(int quality_code, int units_code) {
  char text[16];
  std::snprintf(text, sizeof text, "%02d,%d,", quality_code, units_code);
  return text;
}

// A chromaticity coordinate as the meter prints it: ".xxxx".
std::string Coordinate(double value) {
  const long scaled = std::lround(std::clamp(value, 0.0, 0.9999) * 10000);
  char text[16];
  std::snprintf(text, sizeof text, ".%04ld", scaled);
  return text;
}

}  // namespace

Pr650Tristimulus Pr650TristimulusOf(const std::vector<double>& radiance) {
  return TristimulusOf(radiance, WavelengthGrid::Pr650());
}

Pr650Tristimulus TristimulusOf(const std::vector<double>& radiance, const WavelengthGrid& grid) {
  constexpr double kLumensPerWatt = 683.0;
  Pr650Tristimulus t;
  for (std::size_t i = 0; i < radiance.size() && i < grid.count; ++i) {
    const double nm = grid.at(i);
    const double x_bar = 1.056 * Lobe(nm, 599.8, 37.9, 31.0) + 0.362 * Lobe(nm, 442.0, 16.0, 26.7) -
                         0.065 * Lobe(nm, 501.1, 20.4, 26.2);
    const double y_bar = 0.821 * Lobe(nm, 568.8, 46.9, 40.5) + 0.286 * Lobe(nm, 530.9, 16.3, 31.1);
    const double z_bar = 1.217 * Lobe(nm, 437.0, 11.8, 36.0) + 0.681 * Lobe(nm, 459.0, 26.0, 13.8);
    const double w = kLumensPerWatt * radiance[i] * grid.step_nm;
    t.X += w * x_bar;
    t.Y += w * y_bar;
    t.Z += w * z_bar;
  }
  return t;
}

Pr650ColourTemperature Pr650ColourTemperatureOf(double x, double y) {
  Pr650ColourTemperature t;
  if (y <= 0 || std::abs(0.1858 - y) < 1e-9) return t;
  const double n = (x - 0.3320) / (0.1858 - y);
  t.kelvin = ((449.0 * n + 3525.0) * n + 6823.3) * n + 5520.33;
  if (t.kelvin <= 0) return Pr650ColourTemperature{};
  // CIE 1960 uv of the sample and of the Planckian locus at that temperature.
  const double d = -2 * x + 12 * y + 3;
  const double u = 4 * x / d;
  const double v = 6 * y / d;
  const double k = t.kelvin;
  const double u_locus = (0.860117757 + 1.54118254e-4 * k + 1.28641212e-7 * k * k) /
                         (1 + 8.42420235e-4 * k + 7.08145163e-7 * k * k);
  const double v_locus = (0.317398726 + 4.22806245e-5 * k + 4.20481691e-8 * k * k) /
                         (1 - 2.89741816e-5 * k + 1.61456053e-7 * k * k);
  const double distance = std::hypot(u - u_locus, v - v_locus);
  t.duv = v >= v_locus ? distance : -distance;
  return t;
}

namespace {

// "+.dddd" / "-.dddd": a small signed value as the meter prints coordinates, with a sign.
std::string SignedFraction(double value) {
  const long scaled = std::lround(std::clamp(std::abs(value), 0.0, 0.9999) * 10000);
  char text[16];
  std::snprintf(text, sizeof text, "%c.%04ld", value < 0 ? '-' : '+', scaled);
  return text;
}

}  // namespace

std::string Pr650ColorimetryLine(int report, int quality_code, int units_code,
                                 const Pr650Tristimulus& xyz) {
  const double sum = xyz.X + xyz.Y + xyz.Z;
  const double uv_denominator = xyz.X + 15 * xyz.Y + 3 * xyz.Z;
  const double x = sum > 0 ? xyz.X / sum : 0;
  const double y = sum > 0 ? xyz.Y / sum : 0;
  const double u = uv_denominator > 0 ? 4 * xyz.X / uv_denominator : 0;
  const double v = uv_denominator > 0 ? 9 * xyz.Y / uv_denominator : 0;
  const std::string head = ReportHead(quality_code, units_code);
  switch (report) {
    case 1:
      return head + FormatPr650Number(xyz.Y) + "," + Coordinate(x) + "," + Coordinate(y);
    case 2:
      return head + FormatPr650Number(xyz.X) + "," + FormatPr650Number(xyz.Y) + "," +
             FormatPr650Number(xyz.Z);
    case 3:
      return head + FormatPr650Number(xyz.Y) + "," + Coordinate(u) + "," + Coordinate(v);
    case 4: {
      const Pr650ColourTemperature t =
          sum > 0 ? Pr650ColourTemperatureOf(x, y) : Pr650ColourTemperature{};
      return head + FormatPr650Number(xyz.Y) + "," + FormatPr650Number(t.kelvin) + "," +
             SignedFraction(t.duv);
    }
    case 6:
      return head + FormatPr650Number(xyz.Y) + "," + Coordinate(x) + "," + Coordinate(y) + "," +
             Coordinate(u) + "," + Coordinate(v);
    default:
      return {};
  }
}

std::string Pr650LayoutLine() {
  char text[48];
  std::snprintf(text, sizeof text, "%04d,008.0,%04d.,%04d.,%03d.", kPr650Bands, kPr650FirstNm,
                kPr650FirstNm + kPr650StepNm * (kPr650Bands - 1), kPr650StepNm);
  return text;
}

Pr650SetupResult ApplyPr650Setup(std::string_view fields) {
  std::vector<std::string_view> f;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = fields.find(',', start);
    f.push_back(fields.substr(start, comma == std::string_view::npos ? comma : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  Pr650SetupResult r;
  if (f.size() > 8) {
    r.reply_code = 9;
    return r;
  }
  f.resize(8);  // missing trailing fields are empty: defaults
  auto bad = [&](int position) {
    r.reply_code = position;
    return r;
  };

  // 1: accessory 1, 01–12; only the MS-75 lens (01) is fitted.
  if (!f[0].empty()) {
    const auto a = Digits(f[0]);
    if (!a || *a < 1 || *a > 12) return bad(1);
    if (*a != 1) return bad(50);
  }
  // 2–4: further accessories, none fitted (0 or empty).
  for (int i = 1; i <= 3; ++i) {
    if (f[static_cast<std::size_t>(i)].empty()) continue;
    const auto a = Digits(f[static_cast<std::size_t>(i)]);
    if (!a || *a > 12) return bad(i + 1);
    if (*a != 0) return bad(50);
  }
  // 5: sync: empty or 0 off, 1 = last F result, or 40–250 Hz.
  if (!f[4].empty()) {
    const auto s = Digits(f[4]);
    if (!s || (*s > 1 && (*s < 40 || *s > 250))) return bad(5);
    r.sync = *s != 0;
  }
  // 6: integration, 0 (adaptive) or 10–6000 ms.
  if (!f[5].empty()) {
    const auto t = Digits(f[5]);
    if (!t || (*t != 0 && (*t < 10 || *t > 6000))) return bad(6);
    r.setup.integration_ms = *t;
  }
  // 7: averages 01–99.
  if (!f[6].empty()) {
    const auto n = Digits(f[6]);
    if (!n || *n < 1 || *n > 99 || f[6].size() > 2) return bad(7);
    r.setup.averages = *n;
  }
  // 8: units, 0 English or 1 SI.
  if (!f[7].empty()) {
    const auto u = Digits(f[7]);
    if (!u || *u > 1 || f[7].size() > 1) return bad(8);
  }
  return r;
}

}  // namespace brdf::sim
