// A simulated rig's ETAs are the simulator's (issue 40): brdfd configured with [rig] time_scale
// (brdf-sim's --time-scale) estimates a plan, and the first ETA of its session, for devices that
// many times faster, instead of a real rig's (10:45 falling to 1:02 for a 45 s demo). ValidatePlan
// without a time_scale answers for the daemon's own rig; with one, for that one.
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

v1::PlanSummary Estimate(DaemonRig& rig, const v1::Plan& plan, double time_scale) {
  v1::ValidatePlanRequest request;
  *request.mutable_plan() = plan;
  request.set_time_scale(time_scale);
  v1::ValidatePlanResponse response;
  const grpc::Status st =
      rig.control().ValidatePlan(DaemonRig::Context().get(), request, &response);
  EXPECT_TRUE(st.ok()) << st.error_message();
  EXPECT_TRUE(response.valid());
  return response.summary();
}

// The first ETA of a session of `plan_json` on a daemon whose configuration ends with `extra`,
// and the daemon's estimates of the plan for time scales 0 (its own), 1 and kTimeScale.
struct Etas {
  double first_eta_s = 0;
  double submitted_s = 0;
  double own_s = 0, real_s = 0, scaled_s = 0;
  double real_physical_s = 0, scaled_physical_s = 0;  // the devices' time alone
};

Etas RunSession(const std::string& extra) {
  Etas out;
  DaemonRig rig;
  Status sim = rig.StartSim();
  EXPECT_TRUE(sim.ok()) << sim.ToString();
  Status daemon = rig.StartDaemon(DaemonConfigToml(rig.sim(), rig.database()) + extra);
  EXPECT_TRUE(daemon.ok()) << daemon.ToString();
  if (!sim.ok() || !daemon.ok()) return out;
  const std::string plan_json = plans::SmallRotation();
  v1::Plan plan;
  EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(plan_json, &plan).ok());
  Result<v1::Session> submitted = rig.Submit(plan_json, /*start_now=*/false);
  EXPECT_TRUE(submitted.ok()) << submitted.status().ToString();
  if (!submitted.ok()) return out;
  out.submitted_s = submitted->summary().estimated_duration_s();
  out.own_s = Estimate(rig, plan, 0).estimated_duration_s();
  const v1::PlanSummary real = Estimate(rig, plan, 1), scaled = Estimate(rig, plan, kTimeScale);
  out.real_s = real.estimated_duration_s();
  out.scaled_s = scaled.estimated_duration_s();
  out.real_physical_s = real.physical_lower_bound_s();
  out.scaled_physical_s = scaled.physical_lower_bound_s();
  // Started, nobody answering its first prompt: the ETA of every step still to run.
  v1::StartSessionRequest start;
  start.set_session_id(submitted->session_id());
  v1::StartSessionResponse started;
  EXPECT_TRUE(rig.control().StartSession(DaemonRig::Context().get(), start, &started).ok());
  const v1::Session waiting =
      rig.WaitForState(submitted->session_id(), v1::SESSION_STATE_AWAITING_OPERATOR, 20s);
  out.first_eta_s = waiting.eta_s();
  if (::testing::Test::HasFailure()) std::cerr << rig.log() << "\n";
  StopDaemonExpectingCleanExit(rig);
  return out;
}

TEST(TimeScaleEtaTest, ASimulatedRigsFirstEtaIsTheSimulators) {
  const Etas real = RunSession("");
  const Etas sim = RunSession("[rig]\ntime_scale = " + std::to_string(kTimeScale) + "\n");
  // The daemon's estimates for given scales do not depend on its own.
  EXPECT_DOUBLE_EQ(sim.real_s, real.real_s);
  EXPECT_DOUBLE_EQ(sim.scaled_s, real.scaled_s);
  // Its own: a real rig's unless configured.
  EXPECT_DOUBLE_EQ(real.own_s, real.real_s);
  EXPECT_DOUBLE_EQ(sim.own_s, sim.scaled_s);
  EXPECT_DOUBLE_EQ(real.submitted_s, real.real_s);
  EXPECT_DOUBLE_EQ(sim.submitted_s, sim.scaled_s);
  // The devices' time shrinks by the scale; operator time (30 s a prompt) and the daemon's own
  // waits do not.
  EXPECT_NEAR(sim.scaled_physical_s * kTimeScale, real.real_physical_s,
              1e-6 * real.real_physical_s);
  EXPECT_LT(sim.scaled_s, real.real_s - 0.5 * real.real_physical_s)
      << sim.scaled_s << " s against " << real.real_s;
  // The first ETA: every step left, as estimated for the rig configured (the first prompt's
  // step is pending too, so it is the whole plan's less what the first step took).
  EXPECT_GT(real.first_eta_s, 0.9 * real.real_s);
  EXPECT_LE(real.first_eta_s, real.real_s + 1e-9);
  EXPECT_GT(sim.first_eta_s, 0.9 * sim.scaled_s);
  EXPECT_LE(sim.first_eta_s, sim.scaled_s + 1e-9);
  EXPECT_LT(sim.first_eta_s, real.first_eta_s - 0.5 * real.real_physical_s);
}

}  // namespace
}  // namespace brdf::testing
