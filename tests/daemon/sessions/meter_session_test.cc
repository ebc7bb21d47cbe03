// A demo session on each meter brdf-sim simulates besides the PR-650 (issue 41): brdf-sim started
// with --meter, brdfd configured with [meter] model, a small pose-list plan (a reference, a dark,
// two poses) run to completion through the gRPC API. The rig shows the meter's own model and
// serial number (brdfctl rig prints the same fields), and every reading carries the meter's grid
// (201 bands for a PR-670, 101 for a PR-655, 401 for a CS-2000) and as many values; the session
// says that grid (Session.grid).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/daemon/test_util.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

struct MeterCase {
  const char* key;     // --meter and [meter] model
  const char* model;   // what Identify reports
  const char* serial;  // what brdf-sim's meter reports
  double first_nm;
  double step_nm;
  int bands;
};

const MeterCase kMeters[] = {
    {"pr670", "PR-670", "67012345", 380, 2, 201},
    {"pr655", "PR-655", "67012345", 380, 4, 101},
    {"cs2000", "CS-2000", "20001234", 380, 1, 401},
};

// The daemon tests' configuration with the meter's model (and, for the PR-670's typed commands,
// a short pace).
std::string MeterConfigToml(const SimProcess& sim, const std::string& database,
                            const std::string& key) {
  std::string toml = DaemonConfigToml(sim, database);
  const std::string meter = "[meter]\n";
  toml.insert(toml.find(meter) + meter.size(), "model = \"" + key + "\"\nchar_gap_ms = 1\n");
  return toml;
}

// A reference, a dark and two poses; one average (the CS-2000 has no averaging).
const std::string kDemoPlan = PlanFixture("demo")
                                  .PoseList({{0, 10, 40}, {10, 40, 40}})
                                  .Reference(true)
                                  .DarkWithEachReference()
                                  .Measurement(200, 1)
                                  .Retry(2, 0);

class MeterSessionTest : public ::testing::TestWithParam<MeterCase> {
 protected:
  void TearDown() override {
    if (op_) {
      op_->Stop();
      for (const std::string& e : op_->errors()) ADD_FAILURE() << "operator: " << e;
    }
    StopDaemonExpectingCleanExit(rig_);
  }

  DaemonRig rig_;
  std::unique_ptr<GrpcOperator> op_;
};

TEST_P(MeterSessionTest, ADemoSessionRunsOnTheMeterWithItsOwnGrid) {
  const MeterCase& m = GetParam();
  ASSERT_TRUE(rig_.StartSim({"--meter", m.key}).ok());
  ASSERT_EQ(rig_.sim().meter(), m.key);
  Status daemon = rig_.StartDaemon(MeterConfigToml(rig_.sim(), rig_.database(), m.key));
  ASSERT_TRUE(daemon.ok()) << daemon.ToString();

  Result<v1::Session> submitted = rig_.Submit(kDemoPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  op_ = std::make_unique<GrpcOperator>(rig_, id);
  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 90s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  // The session says its grid (its readings'), in GetSession and in the listing.
  EXPECT_EQ(done.grid().count(), static_cast<std::uint32_t>(m.bands));
  EXPECT_DOUBLE_EQ(done.grid().start_nm(), m.first_nm);
  EXPECT_DOUBLE_EQ(done.grid().step_nm(), m.step_nm);
  {
    v1::ListSessionsRequest list_request;
    v1::ListSessionsResponse listed;
    ASSERT_TRUE(
        rig_.control().ListSessions(DaemonRig::Context().get(), list_request, &listed).ok());
    ASSERT_EQ(listed.sessions_size(), 1);
    EXPECT_EQ(listed.sessions(0).grid().count(), static_cast<std::uint32_t>(m.bands));
  }

  // The rig shows the meter as it identified itself.
  v1::GetRigStatusRequest request;
  v1::RigStatus status;
  ASSERT_TRUE(rig_.control().GetRigStatus(DaemonRig::Context().get(), request, &status).ok());
  EXPECT_EQ(status.meter_serial(), m.serial);
  bool meter_seen = false;
  for (const auto& d : status.devices()) {
    if (d.name() != "meter") continue;
    meter_seen = true;
    EXPECT_EQ(d.model(), m.model);
    EXPECT_EQ(d.state(), v1::CONNECTION_STATE_CONNECTED);
  }
  EXPECT_TRUE(meter_seen);

  // Every planned reading, each on the meter's grid with a value per band.
  Result<std::vector<v1::Reading>> readings = rig_.Readings(id);
  ASSERT_TRUE(readings.ok()) << readings.status().ToString();
  const int planned =
      static_cast<int>(done.summary().sample_readings() + done.summary().reference_readings() +
                       done.summary().dark_readings());
  ASSERT_EQ(static_cast<int>(readings->size()), planned);
  int lit = 0;
  for (const v1::Reading& r : *readings) {
    EXPECT_EQ(r.grid().count(), static_cast<std::uint32_t>(m.bands)) << r.id();
    EXPECT_DOUBLE_EQ(r.grid().start_nm(), m.first_nm);
    EXPECT_DOUBLE_EQ(r.grid().step_nm(), m.step_nm);
    EXPECT_EQ(r.radiance_size(), m.bands);
    if (r.kind() != v1::READING_KIND_DARK) {
      double sum = 0;
      for (double v : r.radiance()) sum += v;
      EXPECT_GT(sum, 0) << "reading " << r.id() << " saw no light";
      lit += sum > 0;
    }
  }
  EXPECT_GT(lit, 0);
  Result<DbSessionCounts> db = CountSession(rig_.database(), std::stoll(id));
  ASSERT_TRUE(db.ok()) << db.status().ToString();
  EXPECT_EQ(db->readings, planned);
  EXPECT_EQ(db->duplicate_readings, 0);
  Result<std::string> problems = StorageProblems(rig_.database(), std::stoll(id));
  ASSERT_TRUE(problems.ok()) << problems.status().ToString();
  EXPECT_EQ(*problems, "");
}

std::string MeterName(const ::testing::TestParamInfo<MeterCase>& info) {
  return info.param.key;
}

INSTANTIATE_TEST_SUITE_P(Meters, MeterSessionTest, ::testing::ValuesIn(kMeters), MeterName);

}  // namespace
}  // namespace brdf::testing
