// The simulated Konica Minolta CS-2000 (or CS-2000A, CS-3000) on a pseudo-terminal: the commands
// of docs/cs2000-protocol.md, each answered with one LF-ended line that starts with its check code
// (OK00, ERxx), asking a MeterBackend what it would measure on the meter's grid (380–780 nm,
// 1 nm, 401 values).
//
//   RMTS,1 / RMTS,0            OK00 (remote mode on / off)
//   IDDR                       OK00,<product>,<variation>,<serial> (variation 1 CS-2000,
//                              2 CS-2000A, 0 CS-3000)
//   SPMS,<mode>[,<t>],<nd>     OK00: 0/1 normal/fast (the meter chooses the integration), 2/4
//                              multi-integration (t 2–16 s), 3 manual (t in µs, 9 digits,
//                              5,000–120,000,000); nd 0 off, 1 on, 2 auto. SPMR reads it back
//   SCMS,0 | SCMS,1,<hz×100> | SCMS,2   OK00 (no sync, internal 20–200 Hz, external); SCMR
//   MEAS,1                     OK00,<s> at once (the measuring time), then OK00 or ERxx when done
//   MEAS,0                     OK00 (nothing to cancel: a measurement runs to its end)
//   MEDR,1,<f>,<block>         OK00 then 100 values (block 4: 101) of 380–479, 480–579, 580–679,
//                              680–780 nm: f 0 ASCII ("1.2345e-03"), f 1 float32 in hex
//   MEDR,2,<f>,<set>           set 00: 24 colorimetric values (Le, Lv, X, Y, Z, x, y, u', v', T,
//                              Δuv, λd, Pe, then X10 … Pe10 for the 10° observer); 02: Lv, x, y
//   MEDR,0,0,1                 OK00,<speed mode>,<nd>,<integration µs>
//   anything else              ER00; a bad parameter ER17; data asked for before a measurement,
//                              or after one that failed, ER20
// A measurement fails with ER10 (over the measurement range) when the light overfills the
// detector in a manual integration time, or with ER<n> for the code SerialFaults::quality_code
// forces. brdf-sim's choices where the sources are silent: outside remote mode only RMTS is
// answered; λd and Pe read 0; the 10° observer's values are the 2° ones.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "tools/brdf-sim/meter/endpoint.h"

namespace brdf::sim {

struct Cs2000EndpointOptions {
  LineEndpointOptions line;
  std::string model = "CS-2000";  // "CS-2000A", "CS-3000"
};

class Cs2000Endpoint final : public LineMeterEndpoint {
 public:
  Cs2000Endpoint(MeterBackend& backend, SimControl& control, Cs2000EndpointOptions options);
  ~Cs2000Endpoint() override;

 protected:
  void Handle(const std::string& command) override;
  void OnPowerOn() override;

 private:
  struct Measurement {
    bool valid = false;
    std::vector<double> radiance;
  };

  void Answer(const std::vector<std::string>& fields);
  void SpeedMode(const std::vector<std::string>& p);
  void SyncMode(const std::vector<std::string>& p);
  void Measure();
  void Read(const std::vector<std::string>& p);
  void Spectral(bool hex, int block);
  void Colorimetric(const std::string& set);

  const std::string model_;
  std::atomic<bool> forget_{false};
  MeterSetup setup_;
  int speed_mode_ = 0;
  int speed_time_ = 0;  // multi-integration s, or manual µs
  int nd_ = 2;
  int sync_mode_ = 0;
  int sync_hz100_ = 0;
  int last_integration_us_ = 0;
  Measurement last_;
};

}  // namespace brdf::sim
