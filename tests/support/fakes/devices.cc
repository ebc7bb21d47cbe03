#include "tests/support/fakes/devices.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

namespace brdf::testing {

using namespace std::chrono_literals;

void FakeBench::SetMounted(FakeTarget target) {
  std::lock_guard lock(mu_);
  mounted_ = target;
}
FakeTarget FakeBench::mounted() const {
  std::lock_guard lock(mu_);
  return mounted_;
}
void FakeBench::SetPose(const Pose& pose) {
  std::lock_guard lock(mu_);
  pose_ = pose;
}
Pose FakeBench::pose() const {
  std::lock_guard lock(mu_);
  return pose_;
}

void FakeFaultSwitch::Set(const FakeFaults& faults) {
  std::lock_guard lock(mu_);
  faults_ = faults;
}
FakeFaults FakeFaultSwitch::faults() const {
  std::lock_guard lock(mu_);
  return faults_;
}
FakeCounts FakeFaultSwitch::counts() const {
  std::lock_guard lock(mu_);
  return counts_;
}
Status FakeFaultSwitch::TakeCall() {
  std::lock_guard lock(mu_);
  ++counts_.calls;
  if (faults_.fail_next <= 0) return Status::Ok();
  --faults_.fail_next;
  ++counts_.failures;
  return faults_.failure;
}
void FakeFaultSwitch::CountConnect() {
  std::lock_guard lock(mu_);
  ++counts_.connects;
}
bool FakeFaultSwitch::unreachable() const {
  std::lock_guard lock(mu_);
  return faults_.unreachable;
}

Status FakeWait(std::chrono::steady_clock::duration d, const CallContext& ctx) {
  const auto until = std::chrono::steady_clock::now() + d;
  for (;;) {
    if (ctx.cancelled()) return Cancelled("fake device: " + ctx.cancel().reason());
    const auto now = std::chrono::steady_clock::now();
    if (now >= until) return Status::Ok();
    if (ctx.expired()) return Timeout("fake device: deadline passed");
    const auto step = std::min<std::chrono::steady_clock::duration>({until - now, 2ms});
    (void)ctx.cancel().WaitFor(step);
  }
}

namespace {

std::chrono::steady_clock::duration Scaled(double simulated_ms, double time_scale) {
  return std::chrono::microseconds(static_cast<long long>(simulated_ms * 1000.0 / time_scale));
}

}  // namespace

// ---- meter ------------------------------------------------------------------------------------

FakeMeter::FakeMeter(std::shared_ptr<FakeBench> bench, std::shared_ptr<FakeFaultSwitch> faults,
                     FakeMeterOptions options)
    : bench_(std::move(bench)), faults_(std::move(faults)), options_(std::move(options)) {}

Status FakeMeter::Connect(const CallContext& ctx) {
  if (ctx.cancelled()) return Cancelled("fake meter: connect cancelled");
  faults_->CountConnect();
  if (faults_->unreachable()) return Disconnected("fake meter: not answering");
  connected_ = true;
  return Status::Ok();
}

void FakeMeter::Disconnect() {
  connected_ = false;
  held_ = false;
}

Status FakeMeter::CheckLink() {
  if (faults_->unreachable()) connected_ = false;
  if (!connected_) return Disconnected("fake meter: not connected");
  return Status::Ok();
}

Result<drivers::MeterIdentity> FakeMeter::Identify(const CallContext&) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  return drivers::MeterIdentity{"PR-650", options_.serial_number, options_.grid};
}

Status FakeMeter::Configure(const drivers::MeasurementSettings& settings, const CallContext&) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  if (settings.integration_ms != 0 &&
      (settings.integration_ms < 10 || settings.integration_ms > 6000)) {
    return InvalidArgument("fake meter: integration " + std::to_string(settings.integration_ms) +
                           " ms outside 10–6000");
  }
  if (settings.averages < 1 || settings.averages > 99) {
    return InvalidArgument("fake meter: averages outside 1–99");
  }
  settings_ = settings;
  return Status::Ok();
}

double FakeMeter::Radiance(FakeTarget target, const Directions& d, double nm) {
  constexpr double kPi = 3.14159265358979323846;
  // A warm lamp: rising towards the red.
  const double lamp = 0.01 * (0.5 + (nm - 380.0) / 400.0);
  if (target == FakeTarget::kDark) return lamp * 1e-4;
  if (target == FakeTarget::kWhite) return lamp;
  // The sample: a smooth, direction-dependent reflectance (diffuse + a broad lobe).
  const double ci = std::cos(d.theta_i * kPi / 180.0);
  const double co = std::cos(d.theta_o * kPi / 180.0);
  const double dphi = std::cos((d.phi_o - d.phi_i) * kPi / 180.0);
  const double reflectance = 0.25 + 0.15 * ci * co + 0.05 * dphi * (nm - 380.0) / 400.0;
  return lamp * reflectance;
}

Result<drivers::MeasurementOutcome> FakeMeter::Measure(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  held_ = false;
  const FakeFaults faults = faults_->faults();
  const int integration =
      settings_.integration_ms == 0 ? options_.adaptive_integration_ms : settings_.integration_ms;
  const double simulated_ms = static_cast<double>(integration) * settings_.averages;
  BRDF_RETURN_IF_ERROR(FakeWait(Scaled(simulated_ms, options_.time_scale) + faults.delay, ctx));
  if (Status injected = faults_->TakeCall(); !injected.ok()) return injected;

  const FakeTarget target = bench_->mounted();
  const Directions d = PoseToDirections(bench_->pose(), options_.convention);
  const WavelengthGrid grid = faults.grid && faults_->counts().calls > faults.grid_after_calls
                                  ? *faults.grid
                                  : options_.grid;
  last_ = drivers::SpectrumReport();
  last_.grid = grid;
  last_.radiance.resize(grid.count);
  double integrated = 0;
  for (std::size_t i = 0; i < grid.count; ++i) {
    last_.radiance[i] = Radiance(target, d, grid.at(i));
    integrated += last_.radiance[i] * grid.step_nm;
  }
  drivers::MeasurementOutcome outcome;
  // A dark reads weak light (the PR-650 reports 10 and the dark policy accepts it flagged).
  outcome.quality_code = target == FakeTarget::kDark ? 10 : 0;
  outcome.flagged = target == FakeTarget::kDark;
  outcome.integration_ms = settings_.integration_ms;
  last_.quality_code = outcome.quality_code;
  last_.integrated = integrated;
  held_ = true;
  return outcome;
}

Result<drivers::SpectrumReport> FakeMeter::TransferSpectrum(const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  if (ctx.cancelled()) return Cancelled("fake meter: transfer cancelled");
  if (!held_) return FailedPrecondition("fake meter: no measurement to transfer");
  return last_;
}

// ---- stage ------------------------------------------------------------------------------------

FakeStage::FakeStage(std::shared_ptr<FakeBench> bench, std::shared_ptr<FakeFaultSwitch> faults,
                     FakeStageOptions options)
    : bench_(std::move(bench)), faults_(std::move(faults)), options_(options) {}

Status FakeStage::Connect(const CallContext& ctx) {
  if (ctx.cancelled()) return Cancelled("fake stage: connect cancelled");
  faults_->CountConnect();
  if (faults_->unreachable()) return Disconnected("fake stage: not answering");
  connected_ = true;
  return Status::Ok();
}

void FakeStage::Disconnect() {
  connected_ = false;
}

Status FakeStage::CheckLink() {
  if (faults_->unreachable()) connected_ = false;
  if (!connected_) return Disconnected("fake stage: not connected");
  return Status::Ok();
}

bool FakeStage::HasAxis(drivers::Axis axis) const {
  switch (axis) {
    case drivers::Axis::kGamma:
      return options_.has_gamma;
    case drivers::Axis::kDelta:
      return options_.has_delta;
    default:
      return true;
  }
}

Status FakeStage::MoveTo(const drivers::StageTarget& target, const CallContext& ctx) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  const std::optional<double> wanted[4] = {target.alpha, target.beta, target.gamma, target.delta};
  Pose to = bench_->pose();
  double* axes[4] = {&to.alpha, &to.beta, &to.gamma, &to.delta};
  double farthest = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (!wanted[i].has_value()) continue;
    const auto axis = static_cast<drivers::Axis>(i);
    if (!HasAxis(axis)) {
      return InvalidArgument(std::string("fake stage: no ") + drivers::AxisName(axis) + " axis");
    }
    if (*wanted[i] < options_.min_deg[i] || *wanted[i] > options_.max_deg[i]) {
      return InvalidArgument(std::string("fake stage: ") + drivers::AxisName(axis) + " " +
                             std::to_string(*wanted[i]) + "° outside travel");
    }
    farthest = std::max(farthest, std::abs(*wanted[i] - *axes[i]));
    *axes[i] = *wanted[i];
  }
  CancelToken stop;
  {
    std::lock_guard lock(stop_mu_);
    stop = stop_;
  }
  const FakeFaults faults = faults_->faults();
  const double simulated_ms = farthest / options_.speed_deg_s * 1000.0;
  const auto wait = Scaled(simulated_ms, options_.time_scale) + faults.delay;
  // Either the caller's cancel or a Stop() ends the move where it is.
  const auto until = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < until) {
    if (stop.cancelled()) return Cancelled("fake stage: stopped");
    BRDF_RETURN_IF_ERROR(FakeWait(std::min<std::chrono::steady_clock::duration>(
                                      {until - std::chrono::steady_clock::now(), 2ms}),
                                  ctx));
  }
  BRDF_RETURN_IF_ERROR(faults_->TakeCall());
  bench_->SetPose(to);
  return Status::Ok();
}

Result<drivers::AxisState> FakeStage::ReadAxis(drivers::Axis axis, const CallContext&) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  if (!HasAxis(axis)) {
    return InvalidArgument(std::string("fake stage: no ") + drivers::AxisName(axis) + " axis");
  }
  const Pose p = bench_->pose();
  const double positions[4] = {p.alpha, p.beta, p.gamma, p.delta};
  drivers::AxisState state;
  state.position_deg = positions[static_cast<std::size_t>(axis)];
  state.in_position = true;
  state.ready = true;
  return state;
}

Result<Pose> FakeStage::ReadPose(const CallContext&) {
  BRDF_RETURN_IF_ERROR(CheckLink());
  Pose p = bench_->pose();
  if (!options_.has_gamma) p.gamma = 0;
  if (!options_.has_delta) p.delta = 0;
  return p;
}

Status FakeStage::ResetAlarm(drivers::Axis, const CallContext&) {
  return CheckLink();
}

Status FakeStage::Home(drivers::Axis axis, const CallContext& ctx) {
  drivers::StageTarget target;
  std::optional<double>* axes[4] = {&target.alpha, &target.beta, &target.gamma, &target.delta};
  *axes[static_cast<std::size_t>(axis)] = 0.0;
  return MoveTo(target, ctx);
}

Status FakeStage::Stop(const CallContext&) {
  std::lock_guard lock(stop_mu_);
  stop_.Cancel("stage stopped");
  stop_ = CancelToken();
  return Status::Ok();
}

}  // namespace brdf::testing
