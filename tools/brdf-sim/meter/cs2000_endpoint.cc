#include "tools/brdf-sim/meter/cs2000_endpoint.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/wavelength_grid.h"
#include "tools/brdf-sim/meter/pr650_protocol.h"

namespace brdf::sim {

namespace {

constexpr int kOverRange = 10;  // ER10: over measurement range
const WavelengthGrid kGrid{380, 1, 401};

std::vector<std::string> Split(const std::string& command) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = command.find(',', start);
    out.push_back(command.substr(start, comma == std::string::npos ? comma : comma - start));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

std::optional<long> Int(const std::string& s) {
  if (s.empty() || s.size() > 10) return std::nullopt;
  long v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return std::nullopt;
    v = v * 10 + (c - '0');
  }
  return v;
}

std::string Error(int code) {
  char text[8];
  std::snprintf(text, sizeof text, "ER%02d", code);
  return text;
}

std::string Ascii(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4e", v);
  return text;
}

std::string Hex(double v) {
  const float f = static_cast<float>(v);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  char text[16];
  std::snprintf(text, sizeof text, "%08X", bits);
  return text;
}

}  // namespace

Cs2000Endpoint::Cs2000Endpoint(MeterBackend& backend, SimControl& control,
                               Cs2000EndpointOptions options)
    : LineMeterEndpoint(backend, control, std::move(options.line)), model_(options.model) {}

Cs2000Endpoint::~Cs2000Endpoint() {
  Stop();
}

void Cs2000Endpoint::OnPowerOn() {
  forget_ = true;
}

void Cs2000Endpoint::Answer(const std::vector<std::string>& fields) {
  std::string line;
  for (const std::string& f : fields) line += (line.empty() ? "" : ",") + f;
  Reply({line});
}

void Cs2000Endpoint::Handle(const std::string& command) {
  if (forget_.exchange(false)) {
    setup_ = MeterSetup{};
    speed_mode_ = sync_mode_ = 0;
    nd_ = 2;
    last_ = Measurement{};
  }
  if (!Admit(command, command == "RMTS,1")) return;
  const std::vector<std::string> p = Split(command);
  const std::string& keyword = p[0];
  if (keyword == "RMTS" && p.size() == 2 && (p[1] == "0" || p[1] == "1")) {
    SetRemote(p[1] == "1");
    Answer({"OK00"});
  } else if (keyword == "IDDR" && p.size() == 1) {
    const std::string variation = model_ == "CS-2000" ? "1" : model_ == "CS-2000A" ? "2" : "0";
    Answer({"OK00", model_ == "CS-2000A" ? "CS-2000" : model_, variation, options().serial_number});
  } else if (keyword == "SPMS") {
    SpeedMode(p);
  } else if (keyword == "SPMR" && p.size() == 1) {
    std::vector<std::string> f = {"OK00", std::to_string(speed_mode_)};
    if (speed_mode_ >= 2) f.push_back(std::to_string(speed_time_));
    f.push_back(std::to_string(nd_));
    Answer(f);
  } else if (keyword == "SCMS") {
    SyncMode(p);
  } else if (keyword == "SCMR" && p.size() == 1) {
    std::vector<std::string> f = {"OK00", std::to_string(sync_mode_)};
    if (sync_mode_ == 1) f.push_back(std::to_string(sync_hz100_));
    Answer(f);
  } else if (keyword == "MEAS" && p.size() == 2 && p[1] == "1") {
    Measure();
  } else if (keyword == "MEAS" && p.size() == 2 && p[1] == "0") {
    Answer({"OK00"});
  } else if (keyword == "MEDR") {
    Read(p);
  } else {
    Answer({Error(0)});
  }
}

void Cs2000Endpoint::SpeedMode(const std::vector<std::string>& p) {
  const std::optional<long> mode = p.size() >= 3 ? Int(p[1]) : std::nullopt;
  const bool timed = mode && (*mode == 2 || *mode == 3 || *mode == 4);
  const std::optional<long> time = timed && p.size() == 4 ? Int(p[2]) : std::nullopt;
  const std::optional<long> nd = Int(p.back());
  bool ok = mode && *mode <= 4 && nd && *nd <= 2 && p.size() == (timed ? 4u : 3u);
  if (ok && (*mode == 2 || *mode == 4)) ok = time && *time >= 2 && *time <= 16;
  if (ok && *mode == 3) ok = time && *time >= 5000 && *time <= 120000000;
  if (!ok) {
    Answer({Error(17)});
    return;
  }
  speed_mode_ = static_cast<int>(*mode);
  speed_time_ = timed ? static_cast<int>(*time) : 0;
  nd_ = static_cast<int>(*nd);
  setup_.integration_ms = speed_mode_ == 3 ? static_cast<int>(*time / 1000) : 0;
  Answer({"OK00"});
}

void Cs2000Endpoint::SyncMode(const std::vector<std::string>& p) {
  const std::optional<long> mode = p.size() >= 2 ? Int(p[1]) : std::nullopt;
  const std::optional<long> hz = p.size() == 3 ? Int(p[2]) : std::nullopt;
  const bool ok = mode && ((*mode != 1 && p.size() == 2 && *mode <= 2) ||
                           (*mode == 1 && hz && *hz >= 2000 && *hz <= 20000));
  if (!ok) {
    Answer({Error(17)});
    return;
  }
  sync_mode_ = static_cast<int>(*mode);
  sync_hz100_ = hz.value_or(0);
  Answer({"OK00"});
}

void Cs2000Endpoint::Measure() {
  const std::optional<Taken> taken = TakeMeasurement(setup_, [this](const Taken& t) {
    // The measuring time, in whole seconds, before the measurement runs.
    const long seconds = std::max(1L, std::lround(std::ceil(t.measurement.duration_s)));
    Answer({"OK00", std::to_string(seconds)});
  });
  if (!taken) return;
  const SimMeasurement& m = taken->measurement;
  int code = m.quality_code == 19 && setup_.integration_ms > 0 ? kOverRange : 0;
  if (taken->forced_code) code = *taken->forced_code;
  last_integration_us_ = m.integration_ms * 1000;
  last_.valid = code == 0 && !taken->no_data;
  last_.radiance = m.radiance;
  last_.radiance.resize(kGrid.count, 0.0);
  Answer({code == 0 ? "OK00" : Error(code)});
}

void Cs2000Endpoint::Read(const std::vector<std::string>& p) {
  if (p.size() != 4) {
    Answer({Error(17)});
    return;
  }
  if (p[1] == "0") {
    Answer({"OK00", std::to_string(speed_mode_), std::to_string(nd_),
            std::to_string(last_integration_us_)});
    return;
  }
  if (!last_.valid) {
    Answer({Error(20)});
    return;
  }
  const std::optional<long> block = Int(p[3]);
  if (p[1] == "1" && (p[2] == "0" || p[2] == "1") && block && *block >= 1 && *block <= 4) {
    Spectral(p[2] == "1", static_cast<int>(*block));
  } else if (p[1] == "2" && p[2] == "0") {
    Colorimetric(p[3]);
  } else {
    Answer({Error(17)});
  }
}

void Cs2000Endpoint::Spectral(bool hex, int block) {
  const std::size_t first = static_cast<std::size_t>(block - 1) * 100;
  const std::size_t count = block == 4 ? 101 : 100;
  std::string line = "OK00";
  for (std::size_t i = first; i < first + count; ++i) {
    line += "," + (hex ? Hex(last_.radiance[i]) : Ascii(last_.radiance[i]));
  }
  Reply({line}, TakeVanish());
}

void Cs2000Endpoint::Colorimetric(const std::string& set) {
  const Pr650Tristimulus t = TristimulusOf(last_.radiance, kGrid);
  const double sum = t.X + t.Y + t.Z;
  const double d = t.X + 15 * t.Y + 3 * t.Z;
  const double x = sum > 0 ? t.X / sum : 0, y = sum > 0 ? t.Y / sum : 0;
  const double u = d > 0 ? 4 * t.X / d : 0, v = d > 0 ? 9 * t.Y / d : 0;
  const Pr650ColourTemperature ct = Pr650ColourTemperatureOf(x, y);
  double le = 0;
  for (double r : last_.radiance) le += r * kGrid.step_nm;
  std::vector<double> values;
  if (set == "00") {
    const std::vector<double> observer = {t.X, t.Y, t.Z, x, y, u, v, ct.kelvin, ct.duv, 0, 0};
    values = {le, t.Y};
    values.insert(values.end(), observer.begin(), observer.end());
    values.insert(values.end(), observer.begin(), observer.end());
  } else if (set == "02") {
    values = {t.Y, x, y};
  } else {
    Answer({Error(17)});
    return;
  }
  std::vector<std::string> fields = {"OK00"};
  for (double value : values) fields.push_back(Ascii(value));
  Answer(fields);
}

}  // namespace brdf::sim
