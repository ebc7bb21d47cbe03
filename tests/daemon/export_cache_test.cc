// ExportInterpolants (daemon/api/export_cache.h): the exports' interpolants kept per session
// snapshot and settings, one builder at a time, within the memory budget.
#include "daemon/api/export_cache.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/uncertain_chain.h"
#include "core/uncertainty/loaded_budget.h"
#include "daemon/api/export_loads.h"
#include "daemon/config/config.h"

namespace brdf::daemon {
namespace {

// A session copy with `readings` readings (ids 1…n): only its identity and size matter here.
std::shared_ptr<const SessionReadings> SessionCopy(std::int64_t id, int readings) {
  auto s = std::make_shared<SessionReadings>();
  s->id = id;
  s->name = "s" + std::to_string(id);
  for (int i = 1; i <= readings; ++i) {
    Reading r;
    r.id = i;
    r.spectrum.values.assign(101, 0.5);
    s->readings.push_back(std::move(r));
  }
  return s;
}

// A real interpolant over a few samples (nearest neighbour, no fill chain), counting its builds.
ExportInterpolants::Build Builder(std::atomic<int>* builds,
                                  std::chrono::milliseconds take = std::chrono::milliseconds(0)) {
  return [builds, take]() -> Result<exports::SessionInterpolant> {
    builds->fetch_add(1);
    std::this_thread::sleep_for(take);
    exports::DerivedSamples derived;
    derived.grid = WavelengthGrid::Pr650();
    for (int k = 0; k < 8; ++k) {
      exports::DerivedSample s;
      s.reading_id = k + 1;
      s.iso = {5.0 * k, 10.0 + 3 * k, 20.0 * k};
      s.values.assign(101, 0.1 * (k + 1));
      derived.samples.push_back(std::move(s));
    }
    return exports::BuildSessionInterpolant(std::move(derived), interp::Method::kNearest, {},
                                            exports::FillPolicy::kNone,
                                            CallContext::WithTimeout(std::chrono::minutes(1)));
  };
}

// A loaded session's bytes count each reading's budget in the form it keeps (LoadedBudget: the
// blend form's double independent part and float rows, the white standard's doubles), and a
// not_estimated list consecutive readings share once.
TEST(ExportInterpolantsTest, ASessionsBytesCountItsReadingsLoadedBudgets) {
  constexpr std::size_t kBands = 401;
  constexpr std::size_t kShared = 7;
  auto notes = std::make_shared<const std::vector<std::string>>(
      std::vector<std::string>{std::string(200, 'n')});
  auto loaded = std::make_shared<uncertainty::LoadedBudget>();
  loaded->blend.bands = kBands;
  loaded->blend.independent.assign(kBands, 1e-3);
  loaded->blend.keys.resize(kShared);
  loaded->blend.shared_rows.assign(kShared * kBands, 1e-4f);
  loaded->blend.not_estimated = notes;
  loaded->blendable = true;
  loaded->white_standard.assign(kBands, 1e-3);
  auto session = [&](int readings, bool budgets) {
    SessionReadings s;
    for (int i = 0; i < readings; ++i) {
      Reading r;
      r.spectrum.values.assign(kBands, 0.5);
      r.brdf_u.assign(kBands, 1e-3);
      if (budgets) r.budget = loaded;
      s.readings.push_back(std::move(r));
    }
    return s;
  };
  const std::uint64_t plain = SharedSessionLoads::BytesOf(session(1, false));
  const std::uint64_t one = SharedSessionLoads::BytesOf(session(1, true)) - plain;
  const std::uint64_t arrays = 2 * kBands * sizeof(double) + kShared * kBands * sizeof(float);
  EXPECT_GE(one, arrays + 200);
  EXPECT_LT(one, arrays + 2048) << "the form kept, not a whole budget's ~39 kB";
  EXPECT_GE(plain, sizeof(Reading) + 2 * kBands * sizeof(double)) << "spectrum and brdf_u";
  // Two readings sharing their notes: the list once.
  const std::uint64_t two = SharedSessionLoads::BytesOf(session(2, true)) -
                            SharedSessionLoads::BytesOf(session(2, false));
  EXPECT_LT(two, 2 * one - 200);
}

TEST(ExportInterpolantsTest, TheSecondExportOfASnapshotReusesTheFirstsInterpolant) {
  MemoryBudget budget(1024);
  ExportInterpolants cache(budget);
  const auto session = SessionCopy(1, 10);
  std::atomic<int> builds{0};
  bool built = false;
  Result<exports::SessionInterpolant> first = cache.Get(session, {}, Builder(&builds), &built);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_TRUE(built);
  Result<exports::SessionInterpolant> second = cache.Get(session, {}, Builder(&builds), &built);
  ASSERT_TRUE(second.ok());
  EXPECT_FALSE(built);
  EXPECT_EQ(builds.load(), 1);
  // The same parts, a chain of its own: the second export's tally starts at zero.
  EXPECT_EQ(second->interpolator, first->interpolator);
  EXPECT_EQ(second->derived, first->derived);
  EXPECT_NE(second->chain.get(), first->chain.get());
  std::vector<double> out(101);
  ASSERT_EQ(first->chain->Source()({5, 10, 0}, out), interp::InterpStatus::kOk);
  EXPECT_EQ(first->chain->Tally().asked(), 1U);
  EXPECT_EQ(second->chain->Tally().asked(), 0U);
  const ExportInterpolants::Stats stats = cache.stats();
  EXPECT_EQ(stats.hits, 1U);
  EXPECT_EQ(stats.entries, 1U);
  EXPECT_GT(stats.bytes, 0U);
  EXPECT_EQ(budget.reserved_bytes(), stats.bytes) << "the kept entry is reserved from the budget";

  // Another setting on the same copy: the session and (here) nothing else shared is reserved
  // once, not per entry.
  ExportInterpolants::Settings mirrored;
  mirrored.options.mirror_phi = true;
  ASSERT_TRUE(cache.Get(session, mirrored, Builder(&builds)).ok());
  const ExportInterpolants::Stats two = cache.stats();
  EXPECT_EQ(two.entries, 2U);
  EXPECT_LT(two.bytes, 2 * stats.bytes);
  EXPECT_GT(two.bytes, stats.bytes);
  EXPECT_EQ(budget.reserved_bytes(), two.bytes);
}

// The interpolation term's calibration is kept with the interpolant: the first export with
// uncertainty computes it, the next export of the snapshot finds it computed and uses the same.
TEST(ExportInterpolantsTest, AKeptInterpolantIsCalibratedOnceForEveryExport) {
  MemoryBudget budget(1024);
  ExportInterpolants cache(budget);
  const auto session = SessionCopy(1, 10);
  std::atomic<int> builds{0};
  Result<exports::SessionInterpolant> first = cache.Get(session, {}, Builder(&builds));
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_FALSE(first->calibrations->chosen.computed()) << "a build alone does not calibrate";
  const exports::UncertainChain one = exports::MakeUncertainChain(*first);
  EXPECT_TRUE(first->calibrations->chosen.computed());
  ASSERT_EQ(one.coverage.calibrations.size(), 1u);

  Result<exports::SessionInterpolant> second = cache.Get(session, {}, Builder(&builds));
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(builds.load(), 1);
  EXPECT_EQ(second->calibrations, first->calibrations);
  EXPECT_TRUE(second->calibrations->chosen.computed()) << "computed before the second asks";
  const exports::UncertainChain two = exports::MakeUncertainChain(*second);
  EXPECT_EQ(&exports::ChosenCalibration(*second), &exports::ChosenCalibration(*first));
  EXPECT_EQ(two.coverage.calibrations[0].fit.detail, one.coverage.calibrations[0].fit.detail);
}

TEST(ExportInterpolantsTest, EachSettingIsItsOwnKey) {
  MemoryBudget budget(1024);
  ExportInterpolants cache(budget);
  const auto session = SessionCopy(1, 10);
  std::atomic<int> builds{0};
  ExportInterpolants::Settings base;
  std::vector<ExportInterpolants::Settings> all(7, base);
  all[1].method = interp::Method::kDelaunay;
  all[2].options.mirror_phi = true;
  all[3].options.reciprocity = true;
  all[4].options.axis_scale = {1, 1, 0.5};
  all[5].fill = exports::FillPolicy::kNone;
  all[6].quantity = exports::Quantity::kReflectance;
  for (std::size_t k = 1; k < all.size(); ++k) {
    EXPECT_NE(ExportInterpolants::KeyOf(all[k]), ExportInterpolants::KeyOf(base))
        << ExportInterpolants::KeyOf(all[k]);
  }
  ExportInterpolants::Settings scaled = base;
  scaled.options.axis_scale = {1, 1, 0.5000001};
  EXPECT_NE(ExportInterpolants::KeyOf(scaled), ExportInterpolants::KeyOf(all[4]));
  ASSERT_TRUE(cache.Get(session, all[0], Builder(&builds)).ok());
  ASSERT_TRUE(cache.Get(session, all[2], Builder(&builds)).ok());
  ASSERT_TRUE(cache.Get(session, all[0], Builder(&builds)).ok());
  EXPECT_EQ(builds.load(), 2);
}

TEST(ExportInterpolantsTest, ASessionThatGainedReadingsIsBuiltAgainAndItsOlderCopyDropped) {
  MemoryBudget budget(1024);
  ExportInterpolants cache(budget);
  std::atomic<int> builds{0};
  const auto before = SessionCopy(1, 10);
  ASSERT_TRUE(cache.Get(before, {}, Builder(&builds)).ok());
  const auto other = SessionCopy(2, 10);
  ASSERT_TRUE(cache.Get(other, {}, Builder(&builds)).ok());
  const auto after = SessionCopy(1, 11);  // a new copy: the store had a reading past the old one
  bool built = false;
  ASSERT_TRUE(cache.Get(after, {}, Builder(&builds), &built).ok());
  EXPECT_TRUE(built);
  EXPECT_EQ(builds.load(), 3);
  const ExportInterpolants::Stats stats = cache.stats();
  EXPECT_EQ(stats.entries, 2U) << "the older copy of session 1 is dropped, session 2 kept";
  EXPECT_EQ(stats.evictions, 1U);
  ASSERT_TRUE(cache.Get(other, {}, Builder(&builds), &built).ok());
  EXPECT_FALSE(built);
}

TEST(ExportInterpolantsTest, OneBuilderOthersWaitAndShareIt) {
  MemoryBudget budget(1024);
  ExportInterpolants cache(budget);
  const auto session = SessionCopy(1, 10);
  std::atomic<int> builds{0};
  std::atomic<int> ok{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 6; ++t) {
    threads.emplace_back([&] {
      if (cache.Get(session, {}, Builder(&builds, std::chrono::milliseconds(200))).ok()) ++ok;
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(ok.load(), 6);
  EXPECT_EQ(builds.load(), 1);
}

TEST(ExportInterpolantsTest, AFailedBuildIsNotKeptAndTheNextCallerBuildsAgain) {
  MemoryBudget budget(1024);
  ExportInterpolants cache(budget);
  const auto session = SessionCopy(1, 10);
  int calls = 0;
  const ExportInterpolants::Build failing = [&calls]() -> Result<exports::SessionInterpolant> {
    ++calls;
    return Cancelled("the client went away");
  };
  Result<exports::SessionInterpolant> got = cache.Get(session, {}, failing);
  ASSERT_FALSE(got.ok());
  EXPECT_EQ(got.status().code(), StatusCode::kCancelled);
  std::atomic<int> builds{0};
  ASSERT_TRUE(cache.Get(session, {}, Builder(&builds)).ok());
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(builds.load(), 1);
}

TEST(ExportInterpolantsTest, WhatDoesNotFitIsHandedOverButNotKept) {
  MemoryBudget budget(1024);
  ExportInterpolants tiny(budget, {4, 1024});  // 1 kB: no interpolant fits
  const auto session = SessionCopy(1, 10);
  std::atomic<int> builds{0};
  ASSERT_TRUE(tiny.Get(session, {}, Builder(&builds)).ok());
  ASSERT_TRUE(tiny.Get(session, {}, Builder(&builds)).ok());
  EXPECT_EQ(builds.load(), 2);
  EXPECT_EQ(tiny.stats().entries, 0U);
  EXPECT_EQ(budget.reserved_bytes(), 0U);

  // At most max_entries: the least recently used goes first.
  ExportInterpolants two(budget, {2, 0});
  const auto a = SessionCopy(1, 10), b = SessionCopy(2, 10), c = SessionCopy(3, 10);
  ASSERT_TRUE(two.Get(a, {}, Builder(&builds)).ok());
  ASSERT_TRUE(two.Get(b, {}, Builder(&builds)).ok());
  ASSERT_TRUE(two.Get(a, {}, Builder(&builds)).ok());  // a used last
  ASSERT_TRUE(two.Get(c, {}, Builder(&builds)).ok());  // b out
  EXPECT_EQ(two.stats().entries, 2U);
  bool built = false;
  ASSERT_TRUE(two.Get(a, {}, Builder(&builds), &built).ok());
  EXPECT_FALSE(built);
  ASSERT_TRUE(two.Get(b, {}, Builder(&builds), &built).ok());
  EXPECT_TRUE(built);
}

// The configuration's [export] table bounds the cache (brdfd and brdf-archive both map it with
// ExportInterpolantsOptionsFrom): with max_entries = 1, exporting the next session drops the kept
// interpolant of the one before, whose next export builds again.
TEST(ExportInterpolantsTest, TheConfigurationsExportTableBoundsTheCache) {
  const Result<Config> config = ParseConfig("[export]\nmax_entries = 1\nmax_mb = 64\n", "t");
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  const ExportInterpolants::Options options = ExportInterpolantsOptionsFrom(*config);
  EXPECT_EQ(options.max_entries, 1U);
  EXPECT_EQ(options.max_bytes, 64U << 20);
  const ExportInterpolants::Options defaults = ExportInterpolantsOptionsFrom(Config());
  EXPECT_EQ(defaults.max_entries, 4U);  // without [export]: today's bounds
  EXPECT_EQ(defaults.max_bytes, 0U);    // half the memory budget

  MemoryBudget budget(1024);
  ExportInterpolants one(budget, options);
  const auto first = SessionCopy(1, 10), second = SessionCopy(2, 10);
  std::atomic<int> builds{0};
  bool built = false;
  ASSERT_TRUE(one.Get(first, {}, Builder(&builds)).ok());
  ASSERT_TRUE(one.Get(first, {}, Builder(&builds), &built).ok());
  EXPECT_FALSE(built);  // kept
  ASSERT_TRUE(one.Get(second, {}, Builder(&builds)).ok());
  EXPECT_EQ(one.stats().entries, 1U);
  EXPECT_EQ(one.stats().evictions, 1U);
  ASSERT_TRUE(one.Get(first, {}, Builder(&builds), &built).ok());
  EXPECT_TRUE(built);  // dropped for the second session: built again
  EXPECT_EQ(builds.load(), 3);
}

}  // namespace
}  // namespace brdf::daemon
