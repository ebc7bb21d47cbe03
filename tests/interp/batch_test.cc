// Batch evaluation (core/interp/batch.h): the answers of EvaluateBatch and EvaluateSpectraBatch
// are the sequential answers, in query order, for every thread count and chunk size; sizes are
// checked; progress is reported; cancellation and deadlines stop the batch with the right status.
#include "core/interp/batch.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>

#include "core/interp/octant/octant.h"
#include "interp_test_data.h"

namespace brdf::interp {
namespace {

using testing::AnalyticSpectrum;
using testing::LinearSpectrum;
using testing::MakeSamples;
using testing::PaperGrid;
using testing::Point;
using testing::RandomPoints;

std::vector<double> Flatten(const std::vector<Point>& points) {
  std::vector<double> out;
  for (const Point& p : points) out.insert(out.end(), p.begin(), p.end());
  return out;
}

void ExpectSameAnswer(const Interpolation& a, const Interpolation& b, std::size_t i) {
  SCOPED_TRACE(::testing::Message() << "query " << i);
  ASSERT_EQ(a.status, b.status);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.detail, b.detail);
  EXPECT_EQ(a.spectrum, b.spectrum);
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t k = 0; k < a.vertices.size(); ++k) {
    EXPECT_EQ(a.vertices[k].index, b.vertices[k].index);
    EXPECT_EQ(a.vertices[k].id, b.vertices[k].id);
    EXPECT_EQ(a.vertices[k].coords, b.vertices[k].coords);
    EXPECT_EQ(a.vertices[k].weight, b.vertices[k].weight);
  }
}

// The paper's grid with queries inside and outside it (ok, empty octants, invalid rows).
struct Fixture {
  std::shared_ptr<SampleSet> samples = MakeSamples(PaperGrid(), AnalyticSpectrum(3));
  std::vector<double> queries;
  Fixture() {
    auto q = RandomPoints(3000, {-10, -10, -10}, {100, 100, 190}, 4);
    q.push_back({10, NAN, 5});  // invalid: answered, not an error
    queries = Flatten(q);
  }
};

TEST(BatchTest, EvaluateBatchIsTheSequentialAnswerForAnyThreadCount) {
  Fixture f;
  const std::size_t n = f.queries.size() / 3;
  std::vector<std::unique_ptr<Interpolator>> interps;
  for (Method m : {Method::kOctant, Method::kNearest, Method::kDelaunay}) {
    auto r = MakeInterpolator(m, f.samples);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    interps.push_back(std::move(r).value());
  }
  for (const auto& interp : interps) {
    SCOPED_TRACE(MethodName(interp->method()));
    std::vector<Interpolation> sequential;
    for (std::size_t i = 0; i < n; ++i) {
      sequential.push_back(interp->Evaluate(std::span(f.queries).subspan(i * 3, 3)));
    }
    for (int threads : {1, 2, 3, 8}) {
      for (std::size_t chunk : {1u, 7u, 512u, 100000u}) {
        SCOPED_TRACE(::testing::Message() << threads << " threads, chunk " << chunk);
        BatchOptions options;
        options.threads = threads;
        options.chunk = chunk;
        auto batch = EvaluateBatch(*interp, f.queries, options);
        ASSERT_TRUE(batch.ok()) << batch.status().ToString();
        ASSERT_EQ(batch->size(), n);
        for (std::size_t i = 0; i < n; ++i) ExpectSameAnswer((*batch)[i], sequential[i], i);
      }
    }
  }
}

TEST(BatchTest, SpectraBatchMatchesEvaluateAndFillsFailuresWithNaN) {
  Fixture f;
  const std::size_t n = f.queries.size() / 3;
  auto interp = OctantInterpolator::Create(f.samples).value();
  const auto bands = static_cast<std::size_t>(f.samples->bands());
  BatchPool pool(3);
  for (std::size_t chunk : {1u, 64u, 5000u}) {
    BatchOptions options;
    options.pool = &pool;
    options.chunk = chunk;
    std::vector<InterpStatus> status(n);
    std::vector<double> spectra(n * bands, -1.0);
    ASSERT_TRUE(EvaluateSpectraBatch(*interp, f.queries, status, spectra, options).ok());
    std::size_t ok = 0, failed = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Interpolation r = interp->Evaluate(std::span(f.queries).subspan(i * 3, 3));
      ASSERT_EQ(status[i], r.status) << i;
      const std::vector<double> row(spectra.begin() + static_cast<std::ptrdiff_t>(i * bands),
                                    spectra.begin() + static_cast<std::ptrdiff_t>((i + 1) * bands));
      if (r.status == InterpStatus::kOk) {
        ++ok;
        EXPECT_EQ(row, r.spectrum) << i;
      } else {
        ++failed;
        for (double v : row) EXPECT_TRUE(std::isnan(v)) << i;
      }
    }
    EXPECT_GT(ok, 1000u);
    EXPECT_GT(failed, 100u);
  }
}

TEST(BatchTest, SpectraBatchWorksForEveryMethod) {
  // The default SpectrumAt (through Evaluate) and the methods' own fast paths agree with Evaluate.
  const auto points = RandomPoints(400, {0, 0, 0}, {90, 90, 360}, 8);
  const auto samples = MakeSamples(points, LinearSpectrum(3, 4));
  const auto queries = Flatten(RandomPoints(500, {-5, -5, -5}, {95, 95, 365}, 9));
  const std::size_t n = queries.size() / 3;
  for (Method m : {Method::kOctant, Method::kNearest, Method::kDelaunay}) {
    SCOPED_TRACE(MethodName(m));
    auto interp = MakeInterpolator(m, samples).value();
    std::vector<InterpStatus> status(n);
    std::vector<double> spectra(n * 4);
    BatchOptions options;
    options.threads = 2;
    options.chunk = 33;
    ASSERT_TRUE(EvaluateSpectraBatch(*interp, queries, status, spectra, options).ok());
    for (std::size_t i = 0; i < n; ++i) {
      const Interpolation r = interp->Evaluate(std::span(queries).subspan(i * 3, 3));
      ASSERT_EQ(status[i], r.status);
      if (r.status == InterpStatus::kOk) {
        EXPECT_EQ(std::vector<double>(spectra.begin() + static_cast<std::ptrdiff_t>(i * 4),
                                      spectra.begin() + static_cast<std::ptrdiff_t>(i * 4 + 4)),
                  r.spectrum);
      }
    }
  }
}

TEST(BatchTest, WrongSizesAreRejected) {
  Fixture f;
  auto interp = OctantInterpolator::Create(f.samples).value();
  const std::vector<double> bad_queries(7, 1.0);  // not a multiple of 3
  auto r = EvaluateBatch(*interp, bad_queries);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("multiple"), std::string::npos) << r.status().message();

  const std::vector<double> queries(30, 10.0);  // 10 queries
  std::vector<InterpStatus> status(9);
  std::vector<double> spectra(10 * 101);
  EXPECT_EQ(EvaluateSpectraBatch(*interp, queries, status, spectra).code(),
            StatusCode::kInvalidArgument);
  status.resize(10);
  spectra.resize(10 * 101 - 1);
  EXPECT_EQ(EvaluateSpectraBatch(*interp, queries, status, spectra).code(),
            StatusCode::kInvalidArgument);
  spectra.resize(10 * 101);
  EXPECT_TRUE(EvaluateSpectraBatch(*interp, queries, status, spectra).ok());
  EXPECT_TRUE(EvaluateBatch(*interp, std::span<const double>()).value().empty());
}

TEST(BatchTest, ProgressCountsUpToTheTotal) {
  Fixture f;
  const std::size_t n = f.queries.size() / 3;
  auto interp = OctantInterpolator::Create(f.samples).value();
  std::vector<std::size_t> seen;
  BatchOptions options;
  options.threads = 3;
  options.chunk = 100;
  options.progress = [&](std::size_t done, std::size_t total) {
    EXPECT_EQ(total, n);
    seen.push_back(done);  // calls never overlap
  };
  ASSERT_TRUE(EvaluateBatch(*interp, f.queries, options).ok());
  ASSERT_EQ(seen.size(), (n + 99) / 100);
  for (std::size_t k = 1; k < seen.size(); ++k) EXPECT_GT(seen[k], seen[k - 1]);
  EXPECT_EQ(seen.back(), n);
}

TEST(BatchTest, CancellationAndDeadlineStopTheBatch) {
  Fixture f;
  auto interp = OctantInterpolator::Create(f.samples).value();
  CancelToken token;
  const CallContext context = CallContext::WithTimeout(std::chrono::hours(1), token);
  BatchOptions options;
  options.threads = 2;
  options.chunk = 10;
  options.context = &context;
  std::atomic<int> chunks{0};
  options.progress = [&](std::size_t, std::size_t) {
    if (++chunks == 3) token.Cancel("operator pressed stop");
  };
  auto r = EvaluateBatch(*interp, f.queries, options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_NE(r.status().message().find("operator pressed stop"), std::string::npos);
  EXPECT_LT(chunks.load(), 300);  // stopped long before the 301 chunks

  const CallContext expired = CallContext::WithTimeout(std::chrono::seconds(-1));
  BatchOptions late;
  late.context = &expired;
  std::vector<InterpStatus> status(f.queries.size() / 3);
  std::vector<double> spectra(status.size() * 101);
  EXPECT_EQ(EvaluateSpectraBatch(*interp, f.queries, status, spectra, late).code(),
            StatusCode::kTimeout);
}

TEST(BatchPoolTest, EveryTaskRunsExactlyOnceAndThePoolIsReusable) {
  BatchPool pool(4);
  EXPECT_EQ(pool.threads(), 4);
  for (std::size_t count : {0u, 1u, 2u, 5u, 1000u}) {
    std::vector<std::atomic<int>> hits(count);
    std::mutex mu;
    std::set<std::thread::id> threads;
    pool.ParallelFor(count, [&](std::size_t i) {
      ++hits[i];
      std::lock_guard lock(mu);
      threads.insert(std::this_thread::get_id());
    });
    for (std::size_t i = 0; i < count; ++i) EXPECT_EQ(hits[i].load(), 1) << i;
    EXPECT_LE(threads.size(), 4u);
  }
  BatchPool single(0);  // counts as 1: everything on the caller's thread
  EXPECT_EQ(single.threads(), 1);
  const auto caller = std::this_thread::get_id();
  single.ParallelFor(10, [&](std::size_t) { EXPECT_EQ(std::this_thread::get_id(), caller); });
}

}  // namespace
}  // namespace brdf::interp
