// IndexCache in process, over a real SQLite store filled through storage's own API: the
// quantities it derives from raw readings, snapshot consistency while readings land, cache keys,
// the LRU bound, and its errors.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <thread>
#include <vector>

#include "core/interp/octant/octant.h"
#include "daemon/index/cache.h"
#include "storage/session_store.h"
#include "tests/support/test_env.h"

namespace brdf::daemon {
namespace {

constexpr double kRhoW = 0.98;
const WavelengthGrid kGrid{400, 100, 4};  // 4 bands: enough to tell them apart

// A session whose steps are: reference (white at θi,ref), dark, then `samples` sample steps.
// Its readings are written by AddReading in step order.
class SessionFixture {
 public:
  SessionFixture(storage::SessionStore& store, int samples, bool anisotropic = false)
      : store_(store) {
    storage::NewSession s;
    s.name = "cache test";
    s.plan_kind = "pose_list";
    s.plan_json = anisotropic ? R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]},
                                    "anisotropic": true})"
                              : R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]}})";
    s.created_by_role = "operator";
    s.white_reflectance = kRhoW;
    std::vector<storage::StepRecord> steps;
    auto step = [&](storage::StepKind kind) {
      storage::StepRecord r;
      r.step_index = static_cast<int>(steps.size());
      r.kind = kind;
      steps.push_back(r);
    };
    step(storage::StepKind::kReference);
    step(storage::StepKind::kDark);
    for (int i = 0; i < samples; ++i) step(storage::StepKind::kSample);
    Result<std::int64_t> id = store.CreateSession(s, steps);
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    id_ = id.ok() ? *id : 0;
    EXPECT_TRUE(store.SetSessionState(id_, SessionState::kRunning, "test").ok());
  }

  std::int64_t id() const { return id_; }

  // White: I0 = D + 1 per band, at incidence theta_ref.
  std::int64_t AddReference(double theta_ref) {
    return Add(storage::ReadingKind::kReference, {theta_ref, 0, 0, 0}, {1.1, 2.1, 3.1, 4.1});
  }
  std::int64_t AddDark() { return Add(storage::ReadingKind::kDark, {}, {0.1, 0.1, 0.1, 0.1}); }
  // A sample whose reflectance is `r` in every band: I = D + r·(I0 − D).
  storage::ReadingRecord AddSample(const Directions& d, double r, bool with_reference = true) {
    const std::int64_t id =
        Add(storage::ReadingKind::kSample, d, {0.1 + r * 1, 0.1 + r * 2, 0.1 + r * 3, 0.1 + r * 4},
            with_reference);
    return *store_.GetReading(id);
  }

 private:
  std::int64_t Add(storage::ReadingKind kind, const Directions& d, std::vector<double> spectrum,
                   bool with_reference = true) {
    storage::ReadingRecord r;
    r.kind = kind;
    r.directions = d;
    r.grid = kGrid;
    r.spectrum = std::move(spectrum);
    if (kind == storage::ReadingKind::kSample) {
      if (with_reference) r.reference_reading_id = reference_;
      r.dark_reading_id = dark_;
    }
    Result<std::int64_t> id = store_.CompleteStepWithReading(id_, next_step_++, r);
    EXPECT_TRUE(id.ok()) << id.status().ToString();
    if (kind == storage::ReadingKind::kReference) reference_ = *id;
    if (kind == storage::ReadingKind::kDark) dark_ = *id;
    return id.ok() ? *id : 0;
  }

  storage::SessionStore& store_;
  std::int64_t id_ = 0;
  int next_step_ = 0;
  std::optional<std::int64_t> reference_;
  std::optional<std::int64_t> dark_;
};

class IndexCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = storage::SessionStore::Open(dir_.file("cache.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
  }

  // Samples on a small (θi, θo, φ) grid around (30, 30, 90), reflectance rising with θo.
  static void FillGrid(SessionFixture& s, std::vector<storage::ReadingRecord>* out = nullptr) {
    s.AddReference(10);
    s.AddDark();
    for (double ti : {20.0, 40.0}) {
      for (double to : {20.0, 40.0}) {
        for (double phi : {60.0, 120.0}) {
          auto r = s.AddSample({ti, 0, to, phi}, 0.1 + to / 100);
          if (out != nullptr) out->push_back(r);
        }
      }
    }
  }

  testing::TempDir dir_{"index-cache-test"};
  std::shared_ptr<storage::SessionStore> store_;
};

TEST_F(IndexCacheTest, DerivesRadianceReflectanceAndBrdfFromTheNamedReferenceAndDark) {
  SessionFixture s(*store_, 8);
  std::vector<storage::ReadingRecord> samples;
  FillGrid(s, &samples);
  IndexCache cache(store_);
  const storage::ReadingRecord& r = samples[5];  // θi 40, θo 20, φ 120: reflectance 0.3
  const double coords[] = {40, 20, 120};

  auto value = [&](Quantity q) {
    auto index = cache.Get(s.id(), q, interp::Method::kNearest, {});
    EXPECT_TRUE(index.ok()) << index.status().ToString();
    interp::Interpolation answer = (*index)->interpolator->Evaluate(coords);
    EXPECT_EQ(answer.vertices.at(0).id, r.id);
    return answer.spectrum;
  };
  const std::vector<double> radiance = value(Quantity::kRadiance);
  const std::vector<double> reflectance = value(Quantity::kReflectance);
  const std::vector<double> brdf = value(Quantity::kBrdf);
  const double cos_ratio =
      std::cos(10 * std::numbers::pi / 180) / std::cos(40 * std::numbers::pi / 180);
  for (int b = 0; b < 4; ++b) {
    EXPECT_NEAR(radiance[b], 0.3 * (b + 1), 1e-12);  // I − D
    EXPECT_NEAR(reflectance[b], 0.3, 1e-12);         // (I − D) / (I0 − D)
    EXPECT_NEAR(brdf[b], 0.3 * kRhoW / std::numbers::pi * cos_ratio, 1e-12);
  }
}

TEST_F(IndexCacheTest, ReadersKeepTheirSnapshotWhileNewReadingsBuildTheNext) {
  SessionFixture s(*store_, 9);
  FillGrid(s);
  IndexCache cache(store_);
  auto first = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kDelaunay, {});
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_EQ((*first)->samples->size(), 8u);
  // Same settings, nothing new: the same snapshot.
  auto again = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kDelaunay, {});
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->get(), first->get());

  // A reading lands and is announced: the next query sees it, the held snapshot does not change.
  const storage::ReadingRecord added = s.AddSample({30, 0, 30, 90}, 0.9);
  cache.OnReading(s.id(), added);
  auto next = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kDelaunay, {});
  ASSERT_TRUE(next.ok());
  EXPECT_NE(next->get(), first->get());
  EXPECT_EQ((*next)->samples->size(), 9u);
  EXPECT_EQ((*next)->through_reading_id, added.id);
  EXPECT_EQ((*first)->samples->size(), 8u);
  const double at[] = {30, 30, 90};
  EXPECT_EQ((*next)->interpolator->Evaluate(at).vertices.at(0).id, added.id);
  // The old snapshot still answers, from its own readings.
  interp::Interpolation old = (*first)->interpolator->Evaluate(at);
  for (const auto& v : old.vertices) EXPECT_NE(v.id, added.id);

  // Another method or options are another index over the same readings.
  interp::Options scaled;
  scaled.axis_scale = {1, 1, 0.5};
  auto other = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kDelaunay, scaled);
  ASSERT_TRUE(other.ok());
  EXPECT_NE(other->get(), next->get());
  EXPECT_EQ((*other)->samples.get(), (*next)->samples.get());  // samples shared
}

// Half/difference coordinates are part of an index's key: with both asked for as readings land,
// the incidence octant index is extended and the half/difference one rebuilt, and each snapshot
// answers as a fresh index in its own coordinates over its readings (never the other's).
TEST_F(IndexCacheTest, CoordinatesAreKeptApartAndAHalfDifferenceIndexIsRebuiltAsReadingsLand) {
  constexpr int kLanding = 12;
  SessionFixture s(*store_, 8 + kLanding);
  FillGrid(s);
  IndexCache cache(store_);
  interp::Options incidence;
  interp::Options half;
  half.coordinates = interp::Coordinates::kHalfDifference;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> theta(15, 45), phi(50, 130), r(0.1, 0.9);
  std::vector<std::array<double, 3>> queries;
  for (int i = 0; i < 30; ++i) queries.push_back({theta(rng), theta(rng), phi(rng)});
  auto same_as_fresh = [&](const IndexSnapshot& snap, const interp::Options& options) {
    auto fresh = interp::MakeInterpolator(interp::Method::kOctant, snap.samples, options);
    ASSERT_TRUE(fresh.ok()) << fresh.status().ToString();
    int answered = 0;
    for (const auto& q : queries) {
      const interp::Interpolation a = snap.interpolator->Evaluate(q);
      const interp::Interpolation b = (*fresh)->Evaluate(q);
      ASSERT_EQ(a.status, b.status);
      ASSERT_EQ(a.spectrum.size(), b.spectrum.size());
      for (std::size_t k = 0; k < a.spectrum.size(); ++k) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(a.spectrum[k]),
                  std::bit_cast<std::uint64_t>(b.spectrum[k]));
      }
      answered += a.status == interp::InterpStatus::kOk;
    }
    EXPECT_GT(answered, 0);
  };
  std::uint64_t builds = 0;
  for (int i = 0; i <= kLanding; ++i) {
    if (i > 0) {
      cache.OnReading(s.id(), s.AddSample({theta(rng), 0, theta(rng), phi(rng)}, r(rng)));
    }
    auto a = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, incidence);
    auto h = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, half);
    auto again = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, incidence);
    ASSERT_TRUE(a.ok() && h.ok() && again.ok());
    EXPECT_NE(a->get(), h->get());
    EXPECT_EQ(a->get(), again->get()) << "the incidence index, not the half/difference one";
    EXPECT_EQ((*h)->options.coordinates, interp::Coordinates::kHalfDifference);
    EXPECT_EQ((*a)->samples.get(), (*h)->samples.get());  // the same readings
    same_as_fresh(**a, incidence);
    same_as_fresh(**h, half);
    // Incidence: one build, then extends; half/difference: a build per landing.
    builds += 1;
    EXPECT_EQ(cache.stats().builds, builds + 1) << "after reading " << i;
    EXPECT_EQ(cache.stats().extends, static_cast<std::uint64_t>(i));
  }
}

TEST_F(IndexCacheTest, ReadingsLandingOneByOneExtendTheOctantIndexWithFreshBuildAnswers) {
  constexpr int kLanding = 30;
  SessionFixture s(*store_, 8 + kLanding);
  FillGrid(s);
  IndexCache cache(store_);
  interp::Options options;
  options.mirror_phi = true;
  options.reciprocity = true;
  auto first = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, options);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_EQ(cache.stats().builds, 1u);
  EXPECT_EQ(cache.stats().extends, 0u);

  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> theta(15, 45), phi(50, 130), r(0.1, 0.9);
  std::vector<std::array<double, 3>> queries;
  for (int i = 0; i < 40; ++i) queries.push_back({theta(rng), theta(rng), phi(rng)});
  std::shared_ptr<const IndexSnapshot> previous = *first;
  for (int i = 0; i < kLanding; ++i) {
    // Some readings repeat a pose already taken (exact duplicates: ties go to the earlier one).
    const Directions d =
        i % 5 == 4 ? Directions{20, 0, 40, 60} : Directions{theta(rng), 0, theta(rng), phi(rng)};
    const storage::ReadingRecord added = s.AddSample(d, r(rng));
    cache.OnReading(s.id(), added);
    auto next = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, options);
    ASSERT_TRUE(next.ok()) << next.status().ToString();
    const IndexSnapshot& snap = **next;
    ASSERT_EQ(snap.samples->size(), 9u + static_cast<std::size_t>(i));
    EXPECT_EQ(snap.through_reading_id, added.id);
    // An extend, not a build.
    EXPECT_EQ(cache.stats().builds, 1u) << "reading " << i;
    EXPECT_EQ(cache.stats().extends, static_cast<std::uint64_t>(i + 1));
    // The previous snapshot is unchanged.
    EXPECT_EQ(previous->samples->size(), 8u + static_cast<std::size_t>(i));

    auto fresh = interp::OctantInterpolator::Create(snap.samples, options);
    ASSERT_TRUE(fresh.ok()) << fresh.status().ToString();
    for (const auto& q : queries) {
      const interp::Interpolation a = snap.interpolator->Evaluate(q);
      const interp::Interpolation b = (*fresh)->Evaluate(q);
      ASSERT_EQ(a.status, b.status);
      ASSERT_EQ(a.detail, b.detail);
      ASSERT_EQ(a.vertices.size(), b.vertices.size());
      for (std::size_t k = 0; k < a.vertices.size(); ++k) {
        EXPECT_EQ(a.vertices[k].id, b.vertices[k].id);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(a.vertices[k].weight),
                  std::bit_cast<std::uint64_t>(b.vertices[k].weight));
      }
      ASSERT_EQ(a.spectrum.size(), b.spectrum.size());
      for (std::size_t k = 0; k < a.spectrum.size(); ++k) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(a.spectrum[k]),
                  std::bit_cast<std::uint64_t>(b.spectrum[k]));
      }
    }
    previous = *next;
  }
  // The same readings read by a cache that never saw them land: the same answers.
  IndexCache cold(store_);
  auto rebuilt = cold.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, options);
  ASSERT_TRUE(rebuilt.ok());
  EXPECT_EQ(cold.stats().builds, 1u);
  for (const auto& q : queries) {
    const interp::Interpolation a = previous->interpolator->Evaluate(q);
    const interp::Interpolation b = (*rebuilt)->interpolator->Evaluate(q);
    ASSERT_EQ(a.status, b.status);
    ASSERT_EQ(a.spectrum, b.spectrum);
  }
  // Other methods are rebuilt over the grown set.
  ASSERT_TRUE(cache.Get(s.id(), Quantity::kBrdf, interp::Method::kNearest, {}).ok());
  EXPECT_EQ(cache.stats().builds, 2u);
}

TEST_F(IndexCacheTest, KeepsAtMostMaxSessionsEvictingTheLeastRecentlyUsed) {
  SessionFixture a(*store_, 8);
  FillGrid(a);
  SessionFixture b(*store_, 8);
  FillGrid(b);
  IndexCache::Options options;
  options.max_sessions = 1;
  IndexCache cache(store_, options);
  ASSERT_TRUE(cache.Get(a.id(), Quantity::kBrdf, interp::Method::kNearest, {}).ok());
  ASSERT_TRUE(cache.Get(b.id(), Quantity::kBrdf, interp::Method::kNearest, {}).ok());
  EXPECT_EQ(cache.stats().sessions, 1u);
  EXPECT_EQ(cache.stats().evictions, 1u);
  ASSERT_TRUE(cache.Get(a.id(), Quantity::kBrdf, interp::Method::kNearest, {}).ok());
  EXPECT_EQ(cache.stats().loads, 3u);  // a was read from the store again
  EXPECT_EQ(cache.stats().evictions, 2u);
}

// brdfd and brdf-archive both take the cache's bounds from [index] (IndexCacheOptionsFrom).
TEST_F(IndexCacheTest, TheConfigurationsIndexTableBoundsTheCache) {
  const Result<Config> config = ParseConfig("[index]\nmax_sessions = 1\nmax_mb = 64\n", "lab.toml");
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  const IndexCache::Options options = IndexCacheOptionsFrom(*config);
  EXPECT_EQ(options.max_bytes, std::size_t{64} << 20);
  SessionFixture a(*store_, 8);
  FillGrid(a);
  SessionFixture b(*store_, 8);
  FillGrid(b);
  IndexCache cache(store_, options);
  ASSERT_TRUE(cache.Get(a.id(), Quantity::kBrdf, interp::Method::kNearest, {}).ok());
  ASSERT_TRUE(cache.Get(b.id(), Quantity::kBrdf, interp::Method::kNearest, {}).ok());
  EXPECT_EQ(cache.stats().sessions, 1u);
  EXPECT_EQ(IndexCacheOptionsFrom(Config()).max_sessions, 8u);  // the defaults without [index]
}

// Queries of a current index take shared locks only (IndexCache::FreshHit); they must still see
// every reading announced before they began, while other threads query and readings land.
TEST_F(IndexCacheTest, ConcurrentQueriesSeeEveryReadingAnnouncedBeforeThemWhileReadingsLand) {
  constexpr int kLanding = 40;
  SessionFixture s(*store_, 8 + kLanding);
  FillGrid(s);
  IndexCache cache(store_);
  ASSERT_TRUE(cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, {}).ok());
  std::atomic<std::int64_t> announced{0};
  std::atomic<bool> done{false};
  std::atomic<long> queries{0};
  std::atomic<long> stale{0};
  std::atomic<long> failed{0};
  std::vector<std::thread> readers;
  for (int t = 0; t < 4; ++t) {
    readers.emplace_back([&] {
      while (!done.load()) {
        const std::int64_t before = announced.load();
        auto got = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, {});
        if (!got.ok()) {
          ++failed;
          continue;
        }
        if ((*got)->through_reading_id < before) ++stale;
        ++queries;
      }
    });
  }
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> theta(15, 45), phi(50, 130);
  std::int64_t last = 0;
  for (int i = 0; i < kLanding; ++i) {
    const storage::ReadingRecord added = s.AddSample({theta(rng), 0, theta(rng), phi(rng)}, 0.5);
    cache.OnReading(s.id(), added);
    announced.store(added.id);
    last = added.id;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  done.store(true);
  for (std::thread& t : readers) t.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_EQ(stale.load(), 0);
  EXPECT_GT(queries.load(), kLanding);
  auto final_index = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, {});
  ASSERT_TRUE(final_index.ok());
  EXPECT_EQ((*final_index)->through_reading_id, last);
  EXPECT_EQ((*final_index)->samples->size(), 8u + kLanding);
  const IndexCache::Stats stats = cache.stats();
  EXPECT_EQ(stats.builds + stats.extends + stats.hits, static_cast<std::uint64_t>(queries) + 2);
}

TEST_F(IndexCacheTest, KeepsAtMostMaxIndexesPerSessionDroppingTheLeastRecentlyQueried) {
  SessionFixture s(*store_, 8);
  FillGrid(s);
  IndexCache::Options options;
  options.max_indexes_per_session = 2;
  IndexCache cache(store_, options);
  auto get = [&](interp::Method m) { return cache.Get(s.id(), Quantity::kBrdf, m, {}); };
  ASSERT_TRUE(get(interp::Method::kOctant).ok());
  ASSERT_TRUE(get(interp::Method::kNearest).ok());
  ASSERT_TRUE(get(interp::Method::kOctant).ok());  // a hit: octant is now the most recent
  EXPECT_EQ(cache.stats().hits, 1u);
  ASSERT_TRUE(get(interp::Method::kDelaunay).ok());  // a third index: nearest goes
  EXPECT_EQ(cache.stats().builds, 3u);
  ASSERT_TRUE(get(interp::Method::kOctant).ok());
  EXPECT_EQ(cache.stats().hits, 2u);
  EXPECT_EQ(cache.stats().builds, 3u);
  ASSERT_TRUE(get(interp::Method::kNearest).ok());  // rebuilt
  EXPECT_EQ(cache.stats().builds, 4u);
  EXPECT_EQ(cache.stats().hits, 2u);
}

TEST_F(IndexCacheTest, ErrorsNameTheProblem) {
  IndexCache cache(store_);
  EXPECT_EQ(cache.Get(4242, Quantity::kBrdf, interp::Method::kOctant, {}).status().code(),
            StatusCode::kNotFound);
  EXPECT_EQ(cache.stats().sessions, 0u);  // an unknown session is not kept

  SessionFixture empty(*store_, 8);
  auto none = cache.Get(empty.id(), Quantity::kBrdf, interp::Method::kOctant, {});
  EXPECT_EQ(none.status().code(), StatusCode::kFailedPrecondition);

  SessionFixture s(*store_, 9);
  FillGrid(s);
  s.AddSample({30, 0, 30, 90}, 0.5, /*with_reference=*/false);
  interp::Options wrong;
  wrong.axis_scale = {1, 1};
  auto bad = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kOctant, wrong);
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("options.axis_scale"), std::string::npos);
  // The sample without a reference has a radiance but no reflectance or BRDF.
  auto radiance = cache.Get(s.id(), Quantity::kRadiance, interp::Method::kNearest, {});
  auto brdf = cache.Get(s.id(), Quantity::kBrdf, interp::Method::kNearest, {});
  ASSERT_TRUE(radiance.ok() && brdf.ok());
  EXPECT_EQ((*radiance)->samples->size(), 9u);
  EXPECT_EQ((*brdf)->samples->size(), 8u);
  EXPECT_EQ((*brdf)->skipped, 1u);
  EXPECT_NE((*brdf)->skipped_detail.find("no reference"), std::string::npos);

  SessionFixture aniso(*store_, 2, /*anisotropic=*/true);
  aniso.AddReference(0);
  aniso.AddDark();
  interp::Options mirror;
  mirror.mirror_phi = true;
  auto sym = cache.Get(aniso.id(), Quantity::kBrdf, interp::Method::kOctant, mirror);
  EXPECT_EQ(sym.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(sym.status().message().find("options.mirror_phi"), std::string::npos);
  interp::Options half;
  half.coordinates = interp::Coordinates::kHalfDifference;
  auto hd = cache.Get(aniso.id(), Quantity::kBrdf, interp::Method::kOctant, half);
  EXPECT_EQ(hd.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(hd.status().message().find("options.coordinates"), std::string::npos);
  EXPECT_NE(hd.status().message().find("incidence coordinates"), std::string::npos);
}

}  // namespace
}  // namespace brdf::daemon
