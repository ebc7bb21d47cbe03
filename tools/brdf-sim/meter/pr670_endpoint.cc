#include "tools/brdf-sim/meter/pr670_endpoint.h"

#include <cmath>
#include <cstdio>

#include "tools/brdf-sim/meter/pr650_protocol.h"
#include "tools/brdf-sim/meter/serial_wire.h"

namespace brdf::sim {

namespace {

constexpr int kTooDark = -8;
constexpr const char* kSetupOk = "0000";
constexpr const char* kSetupRefused = "0001";

std::string Format(const char* format, double value) {
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string Code(int code) {
  char text[16];
  std::snprintf(text, sizeof text, "%05d", code);
  return text;
}

// The number after a command's letters ("SE500" → 500), if it is all digits.
std::optional<long> Number(const std::string& command, std::size_t letters) {
  if (command.size() <= letters || command.size() > letters + 7) return std::nullopt;
  long value = 0;
  for (std::size_t i = letters; i < command.size(); ++i) {
    if (command[i] < '0' || command[i] > '9') return std::nullopt;
    value = value * 10 + (command[i] - '0');
  }
  return value;
}

struct Chromaticity {
  double x = 0, y = 0, u = 0, v = 0;
};
Chromaticity ChromaticityOf(const Pr650Tristimulus& t) {
  const double sum = t.X + t.Y + t.Z;
  const double d = t.X + 15 * t.Y + 3 * t.Z;
  Chromaticity c;
  if (sum > 0) c = {t.X / sum, t.Y / sum, 0, 0};
  if (d > 0) {
    c.u = 4 * t.X / d;
    c.v = 9 * t.Y / d;
  }
  return c;
}

}  // namespace

WavelengthGrid Pr670Grid(const std::string& model) {
  return model == "PR-655" ? WavelengthGrid::Pr650() : WavelengthGrid{380, 2, 201};
}

Pr670Endpoint::Pr670Endpoint(MeterBackend& backend, SimControl& control,
                             Pr670EndpointOptions options)
    : LineMeterEndpoint(backend, control, std::move(options.line)),
      model_(options.model),
      grid_(Pr670Grid(options.model)) {
  last_.radiance.assign(grid_.count, 0.0);
}

Pr670Endpoint::~Pr670Endpoint() {
  Stop();
}

void Pr670Endpoint::OnPowerOn() {
  forget_ = true;
}

void Pr670Endpoint::OnCharacter(char c) {
  if (forget_.exchange(false)) {
    setup_ = MeterSetup{};
    last_ = Measurement{};
    last_.radiance.assign(grid_.count, 0.0);
  }
  LineMeterEndpoint::OnCharacter(c);
  if (c == '\r' || c == '\n') return;
  // PHOTO and Q need no line end: the meter acts on the last character.
  const std::string typed = UpperAscii(TrimBlanks(input_));
  if (typed == "PHOTO") {
    input_.clear();
    if (!Admit("PHOTO", true)) return;
    SetRemote(true);
    Reply({"REMOTE MODE"});
  } else if (typed == "Q") {
    input_.clear();
    if (Admit("Q", false)) SetRemote(false);
  }
}

void Pr670Endpoint::Handle(const std::string& command) {
  if (!Admit(command, false)) return;
  const char kind = command[0];
  if (kind == 'S') {
    HandleSetup(command);
    return;
  }
  if (command == "F") {
    Reply({"0000,100.00 Hertz (Period = 10.00 milliseconds)"});
    return;
  }
  if (kind != 'M' && kind != 'D') return;  // not served: no answer
  const std::optional<long> report = Number(command, 1);
  if (!report) return;
  if (kind == 'M') Measure();
  Report(static_cast<int>(*report));
}

void Pr670Endpoint::HandleSetup(const std::string& command) {
  const std::string what = command.substr(0, 2);
  const std::optional<long> value = Number(command, 2);
  bool ok = value.has_value();
  if (ok && what == "SE") {
    ok = *value == 0 || (*value >= 3 && *value <= 30000);
    if (ok) setup_.integration_ms = static_cast<int>(*value);
  } else if (ok && what == "SN") {
    ok = *value >= 1 && *value <= 99;
    if (ok) setup_.averages = static_cast<int>(*value);
  } else if (ok && what == "SS") {
    ok = *value == 0 || *value == 1 || *value == 3;
  } else if (ok && what == "SK") {
    ok = *value >= 20 && *value <= 400;
  } else {
    ok = ok && (what == "SU" || what == "SO");
  }
  Reply({ok ? kSetupOk : kSetupRefused});
}

void Pr670Endpoint::Measure() {
  const std::optional<Taken> taken = TakeMeasurement(setup_);
  if (!taken) return;
  const SimMeasurement& m = taken->measurement;
  int code = m.quality_code == 10 ? kTooDark : 0;  // the PR-670 knows no low-light warning
  if (taken->forced_code) code = *taken->forced_code;
  last_.code = code;
  last_.integrated = m.integrated;
  last_.radiance = m.radiance;
  last_.radiance.resize(grid_.count, 0.0);
}

std::string Pr670Endpoint::Head() const {
  return Code(last_.code) + "," + std::to_string(control_.serial().units_code) + ",";
}

void Pr670Endpoint::Report(int report) {
  if (report == 110 || report == 111) {
    Reply({"00000," + (report == 110 ? options().serial_number : model_)});
    return;
  }
  if (report == 120) {
    char text[64];
    std::snprintf(text, sizeof text, "00000,%zu,0.00,%.0f,%.0f,%.0f,256,7,247", grid_.count,
                  grid_.start_nm, grid_.last_nm(), grid_.step_nm);
    Reply({text});
    return;
  }
  if (last_.code != 0 || report == 0) {
    Reply({Code(last_.code)});  // a failed measurement has no data; report 0 is the code
    return;
  }
  const Pr650Tristimulus t = TristimulusOf(last_.radiance, grid_);
  const Chromaticity c = ChromaticityOf(t);
  const std::string y = Format("%.3e", t.Y);
  switch (report) {
    case 1:
      Reply({Head() + y + "," + Format("%.4f", c.x) + "," + Format("%.4f", c.y)});
      return;
    case 2:
      Reply({Head() + Format("%.3e", t.X) + "," + y + "," + Format("%.3e", t.Z)});
      return;
    case 3:
      Reply({Head() + y + "," + Format("%.4f", c.u) + "," + Format("%.4f", c.v)});
      return;
    case 4: {
      const Pr650ColourTemperature ct = Pr650ColourTemperatureOf(c.x, c.y);
      char cct[16];
      std::snprintf(cct, sizeof cct, "%5ld", std::lround(ct.kelvin));
      Reply({Head() + y + "," + cct + "," + Format("%.4f", ct.duv)});
      return;
    }
    case 6:
      Reply({Head() + y + "," + Format("%.4f", c.x) + "," + Format("%.4f", c.y) + "," +
             Format("%.4f", c.u) + "," + Format("%.4f", c.v)});
      return;
    case 5:
      break;
    default:
      return;  // not served: no answer
  }
  std::size_t peak = 0;
  double photons = 0;
  for (std::size_t i = 0; i < last_.radiance.size(); ++i) {
    if (last_.radiance[i] > last_.radiance[peak]) peak = i;
    // Photons per second: L λ / (h c), λ in m.
    photons +=
        last_.radiance[i] * grid_.at(i) * 1e-9 / (6.62607015e-34 * 299792458.0) * grid_.step_nm;
  }
  std::vector<std::string> lines;
  lines.reserve(grid_.count + 1);
  lines.push_back(Head() + Format("%.3e", grid_.at(peak)) + "," + Format("%.3e", last_.integrated) +
                  "," + Format("%.3e", photons));
  for (std::size_t i = 0; i < grid_.count; ++i) {
    lines.push_back(std::to_string(std::lround(grid_.at(i))) + "," +
                    Format("%.3e", last_.radiance[i]));
  }
  Reply(lines, TakeVanish());
}

}  // namespace brdf::sim
