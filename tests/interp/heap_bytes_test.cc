// Interpolator::HeapBytes against what the allocator holds for an index (glibc's mallinfo2, in use
// after the build less before it; one thread builds, so the difference is what the index kept).
// The daemon's caches bound their memory by these figures (daemon/index/cache.cc,
// daemon/api/export_cache.cc).
#include <gtest/gtest.h>
#include <malloc.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"

namespace brdf::interp {
namespace {

std::size_t HeapInUse() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

// n readings at random (θi, θo, φ) with a 101-band spectrum each.
std::shared_ptr<const SampleSet> RandomSet(std::size_t n) {
  auto set = std::make_shared<SampleSet>(3, 101);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> theta(0, 85), phi(0, 180), value(0.01, 1);
  std::vector<double> spectrum(101);
  for (std::size_t i = 0; i < n; ++i) {
    const double coords[3] = {theta(rng), theta(rng), phi(rng)};
    for (double& v : spectrum) v = value(rng);
    EXPECT_TRUE(set->Add(static_cast<std::int64_t>(i), coords, spectrum).ok());
  }
  return set;
}

struct Case {
  std::string name;
  Method method;
  Options options;
};

std::vector<Case> Cases() {
  Options mirror;
  mirror.mirror_phi = true;
  Options both = mirror;
  both.reciprocity = true;
  Options half;
  half.coordinates = Coordinates::kHalfDifference;
  Options trend;
  trend.trend = Trend::kBivariate;
  std::vector<Case> cases;
  for (const Method m : {Method::kOctant, Method::kDelaunay, Method::kNearest}) {
    const std::string name = MethodName(m);
    cases.push_back({name, m, {}});
    cases.push_back({name + " mirrored", m, mirror});
    cases.push_back({name + " mirrored and reciprocal", m, both});
    cases.push_back({name + " half/difference", m, half});
    cases.push_back({name + " with trend", m, trend});
  }
  return cases;
}

TEST(InterpolatorHeapBytes, WithinAFewPerCentOfWhatTheIndexHolds) {
  const std::shared_ptr<const SampleSet> set = RandomSet(4000);
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    malloc_trim(0);
    const std::size_t before = HeapInUse();
    Result<std::unique_ptr<Interpolator>> made = MakeInterpolator(c.method, set, c.options);
    ASSERT_TRUE(made.ok()) << made.status().ToString();
    const auto held = static_cast<double>(HeapInUse() - before);
    const auto said = static_cast<double>((*made)->HeapBytes());
    EXPECT_GT(said, 0.95 * held) << "said " << said << " bytes, the heap grew by " << held;
    EXPECT_LT(said, 1.05 * held) << "said " << said << " bytes, the heap grew by " << held;
  }
}

TEST(SampleSetHeapBytes, CountsEveryChunkInFull) {
  const std::shared_ptr<const SampleSet> set = RandomSet(300);  // 3 chunks of 128 samples
  const std::size_t per_chunk =
      SampleSet::kChunkSamples * (sizeof(std::int64_t) + (3 + 101) * sizeof(double));
  EXPECT_GE(set->HeapBytes(), 3 * per_chunk);
  EXPECT_LT(set->HeapBytes(), 3 * per_chunk + 4096);
}

}  // namespace
}  // namespace brdf::interp
