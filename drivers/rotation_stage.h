// The α/β/γ sample holder, plus an optional motorized detector arm (δ). Knows nothing of plans or
// storage: it moves axes to angles and reports where they are.
//
// Threading: calls are safe from any thread; implementations serialize bus access on one owner
// thread per bus (a libmodbus context is not thread-safe). Every call takes a CallContext and never
// blocks past its deadline.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "core/call_context.h"
#include "core/pose.h"
#include "core/status.h"

namespace brdf::drivers {

enum class Axis { kAlpha = 0, kBeta = 1, kGamma = 2, kDelta = 3 };
inline constexpr std::array<Axis, 4> kAllAxes = {Axis::kAlpha, Axis::kBeta, Axis::kGamma,
                                                 Axis::kDelta};
const char* AxisName(Axis axis);  // "alpha", "beta", "gamma", "delta"

struct AxisState {
  double position_deg = 0;   // feedback position converted to degrees
  bool moving = false;       // MOVE
  bool in_position = false;  // IN-POS
  bool ready = false;        // READY
  bool alarm = false;        // ALM-A
  int alarm_code = 0;        // present alarm code, 0 = none
};

// Target for a move. An axis left empty stays where it is.
struct StageTarget {
  std::optional<double> alpha = std::nullopt;
  std::optional<double> beta = std::nullopt;
  std::optional<double> gamma = std::nullopt;
  std::optional<double> delta = std::nullopt;
};

class RotationStage {
 public:
  virtual ~RotationStage() = default;

  virtual Status Connect(const CallContext& ctx) = 0;
  virtual void Disconnect() = 0;
  virtual bool connected() const = 0;

  // Whether this rig has the axis (γ and δ are optional; without δ the operator moves the
  // detector).
  virtual bool HasAxis(Axis axis) const = 0;

  // Moves all named axes (concurrently where the hardware allows) and waits until every one is in
  // position. Refuses targets outside travel limits (kInvalidArgument) before anything moves. An
  // alarm during the move is a kDeviceError with the alarm code; a move that does not finish in
  // distance/speed + margin is kTimeout.
  virtual Status MoveTo(const StageTarget& target, const CallContext& ctx) = 0;

  virtual Result<AxisState> ReadAxis(Axis axis, const CallContext& ctx) = 0;
  // Live pose of all present axes (absent axes read 0).
  virtual Result<Pose> ReadPose(const CallContext& ctx) = 0;

  virtual Status ResetAlarm(Axis axis, const CallContext& ctx) = 0;
  virtual Status Home(Axis axis, const CallContext& ctx) = 0;
  // Stops every axis now (used on abort and pause immediate).
  virtual Status Stop(const CallContext& ctx) = 0;
};

}  // namespace brdf::drivers
