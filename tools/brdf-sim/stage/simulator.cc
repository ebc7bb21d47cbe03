#include "tools/brdf-sim/stage/simulator.h"

#include <utility>

namespace brdf::sim {

std::array<SimAxisConfig, 4> StageSimConfig::DefaultAxes() {
  std::array<SimAxisConfig, 4> axes;
  for (int i = 0; i < 4; ++i) axes[static_cast<std::size_t>(i)].unit_id = i + 1;
  axes[0].min_deg = -90;  // α tilt
  axes[0].max_deg = 90;
  axes[3].min_deg = 0;  // δ lamp–sample–detector angle
  axes[3].max_deg = 180;
  return axes;
}

StageSimulator::StageSimulator(StageSimConfig config, SimControl& control,
                               std::function<void()> power_cycle_meter)
    : config_(std::move(config)),
      control_(control),
      epoch_(std::chrono::steady_clock::now()),
      control_unit_(control, std::move(power_cycle_meter)) {
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (!config_.axes[i].present) continue;
    axes_[i] = std::make_unique<SimAxis>(config_.axes[i], control_, [this] { return NowSim(); });
  }
}

StageSimulator::~StageSimulator() {
  Shutdown();
}

double StageSimulator::NowSim() const {
  return config_.time_scale.ToSim(std::chrono::steady_clock::now() - epoch_);
}

bool StageSimulator::Start(std::string* error) {
  if (config_.serve_tcp && !tcp_.Start(config_.tcp_host, config_.tcp_port, error)) return false;
  if (config_.serve_rtu && !rtu_.Start(error)) {
    tcp_.Stop();
    return false;
  }
  return true;
}

void StageSimulator::Shutdown() {
  tcp_.Stop();
  rtu_.Stop();
}

Pose StageSimulator::LivePose() const {
  std::lock_guard l(mu_);
  double deg[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (axes_[i]) deg[i] = axes_[i]->PositionDeg();
  }
  return Pose{deg[0], deg[1], deg[2], deg[3]};
}

SimAxisSnapshot StageSimulator::AxisSnapshot(int index) const {
  std::lock_guard l(mu_);
  const auto& axis = axes_.at(static_cast<std::size_t>(index));
  return axis ? axis->Snapshot() : SimAxisSnapshot{};
}

StageReply StageSimulator::Handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                  StageTransport transport) {
  if (unit == config_.control_unit_id) {
    return StageReply{StageReply::Kind::kReply, ServePdu(pdu, control_unit_), {}};
  }
  SimAxis* axis = nullptr;
  for (const auto& a : axes_) {
    if (a && a->config().unit_id == unit) axis = a.get();
  }
  if (axis == nullptr) {
    // RTU: nobody answers on the line. TCP: the gateway reports that the target did not answer.
    if (transport == StageTransport::kRtu) return StageReply{StageReply::Kind::kSilent, {}, {}};
    return StageReply{StageReply::Kind::kReply,
                      ExceptionPdu(pdu.empty() ? 0 : pdu[0], modbus::kGatewayTargetFailed),
                      {}};
  }

  struct Fired {
    bool drop = false;
    int exception = 0;
    int delay_ms = 0;
    int outage_ms = 0;
  };
  const auto now = std::chrono::steady_clock::now();
  const bool in_outage = now.time_since_epoch().count() < outage_until_.load();
  const Fired fired = control_.UpdateModbus([in_outage](ModbusFaults& f) {
    Fired r;
    if (in_outage) {
      r.drop = true;
      return r;
    }
    if (f.outage_ms > 0) {
      r.outage_ms = std::exchange(f.outage_ms, 0);
      r.drop = true;
      return r;
    }
    if (f.drop_connection) {
      f.drop_connection = false;
      r.drop = true;
      return r;
    }
    if (f.exception_count > 0 && f.exception_code != 0) {
      --f.exception_count;
      r.exception = f.exception_code;
    }
    if (f.late_count > 0 && f.late_reply_ms > 0) {
      --f.late_count;
      r.delay_ms = f.late_reply_ms;
    }
    return r;
  });
  if (fired.outage_ms > 0) {
    const std::chrono::milliseconds outage(fired.outage_ms);
    outage_until_ = (now + outage).time_since_epoch().count();
    if (transport == StageTransport::kTcp) {
      return StageReply{StageReply::Kind::kDrop, {}, {}, outage};
    }
  }
  if (fired.drop) {
    return StageReply{
        transport == StageTransport::kTcp ? StageReply::Kind::kDrop : StageReply::Kind::kSilent,
        {},
        {}};
  }
  StageReply reply;
  reply.delay = std::chrono::milliseconds(fired.delay_ms);
  if (fired.exception != 0) {
    reply.pdu = ExceptionPdu(pdu.empty() ? 0 : pdu[0], static_cast<std::uint8_t>(fired.exception));
    return reply;
  }
  std::lock_guard l(mu_);
  reply.pdu = ServePdu(pdu, *axis, config_.drive_function_codes);
  return reply;
}

}  // namespace brdf::sim
