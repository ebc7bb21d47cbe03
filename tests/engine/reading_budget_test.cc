// Each sample reading's uncertainty budget (daemon/engine/reading_budget.h): estimated as the
// executor commits it (the pose not yet, the drift from the references so far) and again when the
// session's last step is done, with the pose through the neighbouring readings and the drift to
// the next reference. Sessions on the fake rig store a budget with every sample -- shared through
// the reference, dark, white standard and instrument it really shares -- whose white-standard term
// is the derived BRDF times u(ρw) / ρw; without settings they store none.
#include "daemon/engine/reading_budget.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/readings/derive.h"
#include "daemon/wire/reading.h"
#include "storage/session_readings.h"
#include "storage/session_store.h"
#include "tests/engine/engine_test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using uncertainty::Sharing;

daemon::ReadingBudgetSettings Settings() {
  daemon::ReadingBudgetSettings s;
  s.white_reflectance_u = 0.004;
  s.terms.stray_light = 0.001;
  return s;
}

// A finished session of `plan` on the fake rig, its readings as stored.
class BudgetSession {
 public:
  BudgetSession(std::optional<daemon::ReadingBudgetSettings> settings, const std::string& plan) {
    auto store = storage::SessionStore::Open(dir_.file("brdfd.db").string());
    EXPECT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
    fake_ = MakeFakeRig();
    daemon::SessionManager::Options options = ManagerOptions();
    options.uncertainty = std::move(settings);
    manager_ = std::make_unique<daemon::SessionManager>(store_, fake_.rig, options);
    Result<v1::Session> s = manager_->SubmitPlan(PlanFromJson(plan), kTestOperator, true);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    id_ = IdOf(*s);
    Operator op(*manager_, *fake_.bench, id_);
    const v1::Session done = WaitForSession(
        *manager_, id_,
        [](const v1::Session& x) { return IsState(x, v1::SESSION_STATE_COMPLETED); }, 30s);
    EXPECT_EQ(done.state(), v1::SESSION_STATE_COMPLETED);
    op.Stop();
    auto readings = store_->GetReadings(id_, 0, 100000);
    EXPECT_TRUE(readings.ok());
    readings_ = *readings;
  }
  ~BudgetSession() { manager_->Shutdown(5s); }

  std::int64_t id() const { return id_; }
  const std::vector<storage::ReadingRecord>& readings() const { return readings_; }

 private:
  TempDir dir_{"brdf-budget-test"};
  FakeRig fake_;
  std::shared_ptr<storage::SessionStore> store_;
  std::unique_ptr<daemon::SessionManager> manager_;
  daemon::SessionId id_ = 0;
  std::vector<storage::ReadingRecord> readings_;
};

// The BRDF of each sample reading as core/readings derives it, by reading id.
std::map<std::int64_t, std::vector<double>> DerivedBrdf(
    const std::vector<storage::ReadingRecord>& readings, double white_reflectance) {
  ReadingDeriver deriver(white_reflectance);
  std::map<std::int64_t, std::vector<double>> out;
  for (const storage::ReadingRecord& r : readings) {
    const Reading reading = storage::ToReading(r);
    std::optional<SampleQuantities> q = deriver.Fold(reading);
    if (q.has_value() && q->has(Quantity::kBrdf)) out[r.id] = q->of(Quantity::kBrdf);
  }
  return out;
}

const uncertainty::Component* Find(const uncertainty::ReadingBudget& b, const std::string& name) {
  return b.Find(name);
}

TEST(ReadingBudgetEngineTest, EverySampleIsStoredWithItsBudgetSharedWhereItIsShared) {
  BudgetSession session(Settings(), plans::SmallRotation());
  const auto brdf = DerivedBrdf(session.readings(), 0.99);
  std::vector<std::int64_t> references;
  int samples = 0, with_drift = 0;
  for (const storage::ReadingRecord& r : session.readings()) {
    if (r.kind == ReadingKind::kReference) references.push_back(r.id);
    if (r.kind != ReadingKind::kSample) {
      EXPECT_FALSE(r.uncertainty.has_value()) << "reading " << r.id;
      continue;
    }
    ++samples;
    ASSERT_TRUE(r.uncertainty.has_value()) << "reading " << r.id;
    const uncertainty::ReadingBudget& b = *r.uncertainty;
    EXPECT_EQ(b.quantity, Quantity::kBrdf);
    ASSERT_EQ(b.combined.size(), r.grid.count);
    const auto* white = Find(b, "white_standard");
    const auto* reference = Find(b, "reference_signal");
    const auto* dark = Find(b, "dark_signal");
    ASSERT_TRUE(white && reference && dark && Find(b, "sample_signal") &&
                Find(b, "wavelength_scale") && Find(b, "stray_light"));
    EXPECT_EQ(white->shared, (uncertainty::SharedThrough{Sharing::kWhiteStandard, session.id()}));
    EXPECT_EQ(reference->shared,
              (uncertainty::SharedThrough{Sharing::kReferenceReading, *r.reference_reading_id}));
    EXPECT_EQ(dark->shared,
              (uncertainty::SharedThrough{Sharing::kDarkReading, *r.dark_reading_id}));
    const std::vector<double>& f = brdf.at(r.id);
    for (std::size_t band = 0; band < r.grid.count; band += 25) {
      EXPECT_NEAR(white->contribution[band], f[band] * 0.004 / 0.99, 1e-12 + 1e-9 * f[band]);
      EXPECT_GT(b.combined[band], std::abs(white->contribution[band]));
      EXPECT_GT(b.combined[band], b.independent[band]);
    }
    // Estimated again at the session's end: the pose through the neighbours (here with zero
    // uncertainty, so nothing is named missing), the lamp drift for every reading, the session
    // having more than one reference.
    EXPECT_NE(Find(b, "pose_repeatability"), nullptr) << "reading " << r.id;
    EXPECT_TRUE(b.not_estimated.empty()) << "reading " << r.id << ": " << b.not_estimated[0];
    with_drift += Find(b, "lamp_drift") != nullptr ? 1 : 0;
  }
  EXPECT_GT(samples, 0);
  EXPECT_GE(references.size(), 2u);
  EXPECT_EQ(with_drift, samples);
}

// As committed, a reading knows only the references before it and no neighbours: the pose is not
// estimated, nor the drift before a second reference (or a configured rate).
TEST(ReadingBudgetEngineTest, AtCommitThePoseAndAFirstIntervalsDriftAreNotEstimated) {
  BudgetSession session(Settings(), plans::SmallRotation());
  daemon::ReadingBudgeter budgeter(Settings(), session.id(), 0.99, std::nullopt, std::nullopt, 1);
  int references = 0, checked = 0;
  for (const storage::ReadingRecord& r : session.readings()) {
    if (r.kind != ReadingKind::kSample) {
      budgeter.Observe(r, r.recorded_at);
      references += r.kind == ReadingKind::kReference ? 1 : 0;
      continue;
    }
    Result<uncertainty::ReadingBudget> b = budgeter.Estimate(r, r.recorded_at);
    ASSERT_TRUE(b.ok()) << b.status().message();
    bool pose_missing = false, drift_missing = false;
    for (const std::string& why : b->not_estimated) {
      pose_missing |= why.rfind("pose:", 0) == 0;
      drift_missing |= why.rfind("lamp_drift:", 0) == 0;
    }
    EXPECT_TRUE(pose_missing);
    EXPECT_EQ(drift_missing, references < 2) << "reading " << r.id;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// With an uncertain stage, the session's end gives each sample its pose term along the axes its
// neighbours span (α, β, δ on the rotation grid) and names the axes they do not (always γ).
TEST(ReadingBudgetEngineTest, AtTheSessionsEndThePoseComesFromTheNeighbours) {
  daemon::ReadingBudgetSettings settings = Settings();
  settings.terms.stage.repeatability_deg = {0.1, 0.1, 0.1, 0.1};
  BudgetSession session(settings, plans::SmallRotation());
  int checked = 0;
  std::map<std::string, int> estimated;
  for (const storage::ReadingRecord& r : session.readings()) {
    if (r.kind != ReadingKind::kSample) continue;
    ASSERT_TRUE(r.uncertainty.has_value());
    const uncertainty::Component* pose = Find(*r.uncertainty, "pose_repeatability");
    ASSERT_NE(pose, nullptr) << "reading " << r.id;
    double largest = 0;
    for (double u : pose->contribution) largest = std::max(largest, std::abs(u));
    EXPECT_GT(largest, 0) << "reading " << r.id;
    std::map<std::string, int> missing;
    for (const std::string& why : r.uncertainty->not_estimated) {
      ++missing[why.substr(0, why.find(':'))];
    }
    EXPECT_EQ(missing.count("pose_gamma"), 1u) << "reading " << r.id;
    for (const auto& [name, count] : missing) {
      EXPECT_TRUE(name == "pose_alpha" || name == "pose_beta" || name == "pose_gamma" ||
                  name == "pose_delta")
          << "reading " << r.id << " misses " << name;
    }
    for (const char* axis : {"pose_alpha", "pose_beta", "pose_delta"}) {
      estimated[axis] += missing.count(axis) == 0 ? 1 : 0;
    }
    ++checked;
  }
  EXPECT_GT(checked, 0);
  for (const char* axis : {"pose_alpha", "pose_beta", "pose_delta"}) {
    EXPECT_GT(estimated[axis], 0) << axis << " was estimated for no reading";
  }
}

// The API's Reading carries the stored budget: components with their sharing, the shared reading's
// id only for a reference or dark (the session's are named by session_id), values per band.
TEST(ReadingBudgetEngineTest, TheApisReadingCarriesTheBudget) {
  BudgetSession session(Settings(), plans::SmallRotation());
  int checked = 0;
  for (const storage::ReadingRecord& r : session.readings()) {
    const v1::Reading proto = daemon::ToProtoReading(r, {});
    if (r.kind != ReadingKind::kSample) {
      EXPECT_FALSE(proto.has_uncertainty());
      continue;
    }
    ASSERT_TRUE(proto.has_uncertainty());
    const v1::ReadingUncertainty& u = proto.uncertainty();
    EXPECT_EQ(u.quantity(), v1::QUANTITY_BRDF);
    ASSERT_EQ(u.combined_size(), static_cast<int>(r.grid.count));
    EXPECT_EQ(u.value(10), r.uncertainty->value[10]);
    EXPECT_EQ(u.combined(10), r.uncertainty->combined[10]);
    EXPECT_EQ(u.independent(10), r.uncertainty->independent[10]);
    ASSERT_EQ(u.components_size(), static_cast<int>(r.uncertainty->components.size()));
    for (const v1::UncertaintyComponent& c : u.components()) {
      if (c.name() == "reference_signal") {
        EXPECT_EQ(c.sharing(), v1::UNCERTAINTY_SHARING_REFERENCE_READING);
        EXPECT_EQ(c.shared_id(), *r.reference_reading_id);
      } else if (c.name() == "white_standard") {
        EXPECT_EQ(c.sharing(), v1::UNCERTAINTY_SHARING_WHITE_STANDARD);
        EXPECT_EQ(c.shared_id(), 0);
      } else if (c.name() == "sample_signal") {
        EXPECT_EQ(c.sharing(), v1::UNCERTAINTY_SHARING_INDEPENDENT);
      }
      EXPECT_EQ(c.contribution_size(), static_cast<int>(r.grid.count)) << c.name();
    }
    EXPECT_EQ(u.not_estimated_size(), static_cast<int>(r.uncertainty->not_estimated.size()));
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(ReadingBudgetEngineTest, ThePlansWhiteUncertaintyWinsOverTheConfigurations) {
  std::string plan = plans::SmallRotation().Json();
  plan.insert(plan.find('{') + 1,
              R"("sample": {"whiteReflectance": 0.98, "whiteReflectanceUncertainty": 0.002}, )");
  BudgetSession session(Settings(), plan);
  const auto brdf = DerivedBrdf(session.readings(), 0.98);
  int checked = 0;
  for (const storage::ReadingRecord& r : session.readings()) {
    if (r.kind != ReadingKind::kSample) continue;
    ASSERT_TRUE(r.uncertainty.has_value());
    const auto* white = Find(*r.uncertainty, "white_standard");
    ASSERT_NE(white, nullptr);
    const double f = brdf.at(r.id)[50];
    EXPECT_NEAR(white->contribution[50], f * 0.002 / 0.98, 1e-12 + 1e-9 * f);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(ReadingBudgetEngineTest, WithoutSettingsReadingsAreStoredNotEstimated) {
  BudgetSession session(std::nullopt, plans::TinyPoseList());
  ASSERT_FALSE(session.readings().empty());
  for (const storage::ReadingRecord& r : session.readings()) {
    EXPECT_FALSE(r.uncertainty.has_value()) << "reading " << r.id;
  }
}

TEST(ReadingBudgetEngineTest, SettingsFromTheConfigurationAddTheStagesResolution) {
  daemon::Config config;
  config.uncertainty.stage_repeatability_deg = 0.01;
  config.uncertainty.stage_alignment_deg = 0.02;
  config.uncertainty.wavelength_nm = 1.0;
  config.sample.white_reflectance_uncertainty = 0.003;
  config.stage.beta.counts_per_degree = 100;  // steps of 0.01°: u = 0.01 / √12
  const std::optional<daemon::ReadingBudgetSettings> s = daemon::ReadingBudgetSettingsFrom(config);
  ASSERT_TRUE(s.has_value());
  EXPECT_DOUBLE_EQ(s->white_reflectance_u, 0.003);
  EXPECT_DOUBLE_EQ(s->terms.wavelength_nm, 1.0);
  EXPECT_NEAR(s->terms.stage.repeatability_deg[1], std::hypot(0.01, 0.01 / std::sqrt(12.0)), 1e-15);
  EXPECT_DOUBLE_EQ(s->terms.stage.alignment_deg[3], 0.02);
  config.uncertainty.enabled = false;
  EXPECT_FALSE(daemon::ReadingBudgetSettingsFrom(config).has_value());
}

}  // namespace
}  // namespace brdf::testing
