// Rig::FromConfig: the daemon's configuration ([meter], [stage]) turned into the two drivers: the
// meter's by [meter] model (PR-650; PR-655/670; CS-2000/2000A/3000).
// Stage readings are what the drivers deal in; the zero offsets and signs of [stage.axes.*] map
// them to geometry.md's model angles in core/plan (RigDescription::convention), not here.
#include <spdlog/spdlog.h>

#include <memory>
#include <string>

#include "daemon/config/config.h"
#include "daemon/engine/rig.h"
#include "drivers/cs2000/spectroradiometer.h"
#include "drivers/pr650/spectroradiometer.h"
#include "drivers/pr670/spectroradiometer.h"
#include "drivers/stage/modbus_stage.h"
#include "drivers/stage/profile_file.h"

namespace brdf::daemon {
namespace {

// What every meter's options take from [meter] alike: the line, the pacing, the timeouts, the
// quality policy's overrides and the log (`tag`: "pr650: …").
template <typename Options>
Options LineOptions(const MeterConfig& m, const char* tag) {
  using std::chrono::milliseconds;
  Options o;
  o.port = m.port;
  o.baud = m.baud;
  o.hardware_flow_control = m.hardware_flow_control;
  o.command_pacing = milliseconds(m.pacing_ms);
  o.quiet_gap = milliseconds(m.quiet_gap_ms);
  o.reply_timeout = milliseconds(m.reply_timeout_ms);
  o.measurement_timeout = milliseconds(m.measurement_timeout_ms);
  for (const auto& [code, rule] : m.quality_overrides) o.quality_policy.Set(code, rule);
  o.log = [tag](std::string_view line) { spdlog::debug("{}: {}", tag, line); };
  return o;
}

drivers::Pr650Options MeterOptions(const MeterConfig& m) {
  auto o = LineOptions<drivers::Pr650Options>(m, "pr650");
  o.wake_attempts = m.wake_attempts;
  o.measure_with_spectrum = m.measure_with_spectrum;
  o.wake_settle = std::chrono::milliseconds(m.rts_settle_ms);
  return o;
}

drivers::Pr670Options Pr670MeterOptions(const MeterConfig& m) {
  auto o = LineOptions<drivers::Pr670Options>(m, "pr670");
  o.model = MeterModelName(m.model);
  o.char_gap = std::chrono::milliseconds(m.char_gap_ms);
  o.remote_attempts = m.wake_attempts;
  return o;
}

drivers::Cs2000Options Cs2000MeterOptions(const MeterConfig& m) {
  auto o = LineOptions<drivers::Cs2000Options>(m, "cs2000");
  o.model = MeterModelName(m.model);
  o.nd_filter = m.nd_filter == "off"  ? drivers::cs2000::NdFilter::kOff
                : m.nd_filter == "on" ? drivers::cs2000::NdFilter::kOn
                                      : drivers::cs2000::NdFilter::kAuto;
  o.remote_attempts = m.wake_attempts;
  return o;
}

// The driver of [meter] model, its options checked.
Result<std::unique_ptr<drivers::Spectroradiometer>> MakeMeter(const MeterConfig& m) {
  std::unique_ptr<drivers::Spectroradiometer> meter;
  Status checked;
  switch (FamilyOf(m.model)) {
    case MeterFamily::kPr650: {
      drivers::Pr650Options o = MeterOptions(m);
      checked = drivers::ValidatePr650Options(o);
      meter = std::make_unique<drivers::Pr650Spectroradiometer>(std::move(o));
      break;
    }
    case MeterFamily::kPr670: {
      drivers::Pr670Options o = Pr670MeterOptions(m);
      checked = drivers::ValidatePr670Options(o);
      meter = std::make_unique<drivers::Pr670Spectroradiometer>(std::move(o));
      break;
    }
    case MeterFamily::kCs2000: {
      drivers::Cs2000Options o = Cs2000MeterOptions(m);
      checked = drivers::ValidateCs2000Options(o);
      meter = std::make_unique<drivers::Cs2000Spectroradiometer>(std::move(o));
      break;
    }
  }
  if (!checked.ok()) return checked.WithContext("config [meter]");
  return meter;
}

drivers::stage::AxisConfig Axis(const AxisSettings& a, bool present) {
  drivers::stage::AxisConfig c;
  c.present = present;
  c.bus = 0;
  c.unit_id = a.unit_id;
  c.counts_per_degree = a.counts_per_degree;
  c.zero_offset_counts = 0;  // stage readings; the model-angle offset lives in the convention
  c.min_deg = a.min_deg;
  c.max_deg = a.max_deg;
  c.speed_deg_s = a.speed_deg_s;
  return c;
}

// "az profile", or "profile file /etc/brdfd/stage.toml".
std::string StageProfileLabel(const StageConfig& s) {
  return s.profile_file.empty() ? s.profile + " profile" : "profile file " + s.profile_file;
}

Result<drivers::stage::ModbusStageConfig> StageOptions(const StageConfig& s) {
  drivers::stage::ModbusStageConfig c;
  // The register map: a lab's own file ([stage] profile_file), else a built-in one by name.
  Result<drivers::stage::RegisterProfile> profile =
      s.profile_file.empty() ? drivers::stage::BuiltinProfile(s.profile)
                             : drivers::stage::LoadProfileFile(s.profile_file);
  if (!profile.ok()) {
    return profile.status().WithContext(s.profile_file.empty() ? "config stage.profile"
                                                               : "config stage.profile_file");
  }
  c.profile = std::move(profile).value();
  if (!c.profile.verified_against_hardware) {
    spdlog::warn(
        "stage register profile '{}' is not verified against a drive: check every address, bit "
        "and opcode against the drive's manual (docs/stage-modbus.md) and run brdf-stage-probe",
        c.profile.name);
  }
  drivers::stage::BusConfig bus;
  if (s.transport == "rtu") {
    bus.endpoint = drivers::stage::RtuEndpoint{s.device, s.baud, s.parity, 8, 1};
  } else {
    bus.endpoint = drivers::stage::TcpEndpoint{s.host, s.port};
  }
  bus.response_timeout = std::chrono::milliseconds(s.response_timeout_ms);
  bus.busy_window = std::chrono::milliseconds(s.busy_window_ms);
  c.buses = {bus};
  c.axes[0] = Axis(s.alpha, true);
  c.axes[1] = Axis(s.beta, true);
  c.axes[2] = Axis(s.gamma, s.gamma.present);
  c.axes[3] = Axis(s.delta, s.detector_arm_motorized);
  return c;
}

}  // namespace

Result<std::unique_ptr<Rig>> Rig::FromConfig(const Config& config, Options options) {
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<drivers::Spectroradiometer> meter, MakeMeter(config.meter));
  BRDF_ASSIGN_OR_RETURN(drivers::stage::ModbusStageConfig stage_options,
                        StageOptions(config.stage));
  auto stage = drivers::stage::ModbusStage::Create(stage_options);
  if (!stage.ok()) return stage.status().WithContext("config [stage]");

  options.stage_backoff_max = std::chrono::milliseconds(config.stage.reconnect_max_ms);
  const std::string stage_address =
      config.stage.transport == "rtu" ? config.stage.device
                                      : config.stage.host + ":" + std::to_string(config.stage.port);
  return std::make_unique<Rig>(
      std::move(meter), DeviceInfo{MeterModelName(config.meter.model), config.meter.port},
      std::move(*stage),
      DeviceInfo{"Modbus stage (" + StageProfileLabel(config.stage) + ")", stage_address},
      ToRigDescription(config), options);
}

}  // namespace brdf::daemon
