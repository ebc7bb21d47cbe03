// The simulated PR-670 (or PR-655) on a pseudo-terminal: the letter commands of
// docs/pr670-protocol.md, answered as the meter's manual shows them, asking a MeterBackend what it
// would measure on the meter's grid (201 bands every 2 nm; a PR-655's 101 every 4 nm).
//
//   typed (no line end needed)  PHOTO → "REMOTE MODE" (remote mode on), Q → nothing (off)
//   commands (CR or LF ended)   replies (lines end CR LF); qqqqq the result code ("00000", "-0008")
//   M<n> / D<n>                 measure (M), then report n, or report n of the last measurement:
//     0                         qqqqq
//     1, 3, 6                   qqqqq,U,Y,x,y  /  qqqqq,U,Y,u',v'  /  qqqqq,U,Y,x,y,u',v'
//     2                         qqqqq,U,X,Y,Z
//     4                         qqqqq,U,Y,CCCCC,d.dddd (correlated colour temperature, Δuv)
//     5                         qqqqq,U,peak,integrated,photon / one "380,1.627e-03" per band
//     110, 111, 120             00000,<serial> / 00000,PR-670 / 00000,201,0.00,380,780,2,256,7,247
//   SE<ms> SN<n> SS<0|1|3> SK<hz>  0000 (exposure 0 adaptive or 3–30000 ms, 1–99 averages);
//                               0001 for a value out of range (brdf-sim's choice of code)
//   F                           0000,100.00 Hertz (Period = 10.00 milliseconds)
// A measurement that fails is answered with its code alone: −8 (too dark) when the light
// fills less than the detector's weak level, or the code SerialFaults::quality_code forces.
// Outside remote mode every command but PHOTO goes unanswered. Faults as for the PR-650
// (silent, garbage, truncation, a port that vanishes during report 5) and leave_remote.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "core/wavelength_grid.h"
#include "tools/brdf-sim/meter/endpoint.h"

namespace brdf::sim {

struct Pr670EndpointOptions {
  LineEndpointOptions line;
  std::string model = "PR-670";  // or "PR-655": 101 bands every 4 nm
};

// The grid of a model: the PR-670's 380–780 nm every 2 nm, the PR-655's every 4 nm.
WavelengthGrid Pr670Grid(const std::string& model);

class Pr670Endpoint final : public LineMeterEndpoint {
 public:
  Pr670Endpoint(MeterBackend& backend, SimControl& control, Pr670EndpointOptions options);
  ~Pr670Endpoint() override;

 protected:
  void OnCharacter(char c) override;
  void Handle(const std::string& command) override;
  void OnPowerOn() override;

 private:
  struct Measurement {
    int code = 0;
    double integrated = 0;
    std::vector<double> radiance;  // zeros before the first measurement
  };

  void HandleSetup(const std::string& command);
  void Measure();
  void Report(int report);
  std::string Head() const;  // "qqqqq,U," of the last measurement

  const std::string model_;
  const WavelengthGrid grid_;
  // Set by a power cycle (another thread); the endpoint thread forgets setup_ and last_ then.
  std::atomic<bool> forget_{false};
  MeterSetup setup_;
  Measurement last_;
};

}  // namespace brdf::sim
