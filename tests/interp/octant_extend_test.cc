// Growing an octant index as readings land: SampleSet copies share their storage and grow without
// touching the original, and OctantInterpolator::Extend answers every query exactly as a fresh
// Create over the grown set does (status, vertices, weights, spectrum bit for bit, detail), one
// sample at a time and in bursts, with and without symmetry copies, in 3D and 4D, with duplicate
// points and exact distance ties, before and after the tail is folded into a fresh tree.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "core/interp/octant/octant.h"
#include "tests/interp/interp_test_data.h"

namespace brdf::interp {
namespace {

using testing::LinearSpectrum;
using testing::Point;
using testing::SpectrumFn;

std::uint64_t Bits(double x) {
  return std::bit_cast<std::uint64_t>(x);
}

void ExpectSameBits(std::span<const double> a, std::span<const double> b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(Bits(a[i]), Bits(b[i])) << what << " value " << i << ": " << a[i] << " vs " << b[i];
  }
}

// Every way of asking `grown` (an extended interpolator) gives `fresh`'s answer, bit for bit.
void ExpectSameAnswers(const OctantInterpolator& grown, const OctantInterpolator& fresh,
                       const std::vector<Point>& queries, const std::string& where) {
  const int bands = fresh.bands();
  const auto nb = static_cast<std::size_t>(bands);
  for (std::size_t qi = 0; qi < queries.size(); ++qi) {
    const Point& q = queries[qi];
    const std::string what = where + ", query " + std::to_string(qi);
    const Interpolation a = grown.Evaluate(q);
    const Interpolation b = fresh.Evaluate(q);
    ASSERT_EQ(a.status, b.status) << what;
    ASSERT_EQ(a.detail, b.detail) << what;
    ExpectSameBits(a.spectrum, b.spectrum, what + " spectrum");
    ASSERT_EQ(a.vertices.size(), b.vertices.size()) << what;
    for (std::size_t k = 0; k < a.vertices.size(); ++k) {
      ASSERT_EQ(a.vertices[k].id, b.vertices[k].id) << what << " vertex " << k;
      ASSERT_EQ(a.vertices[k].index, b.vertices[k].index) << what << " vertex " << k;
      ASSERT_EQ(Bits(a.vertices[k].weight), Bits(b.vertices[k].weight)) << what << " vertex " << k;
      ExpectSameBits(a.vertices[k].coords, b.vertices[k].coords, what + " vertex coords");
    }

    std::vector<double> sa(nb, -1.0), sb(nb, -1.0);
    const OctantResult ra = grown.EvaluateInto(q, sa);
    const OctantResult rb = fresh.EvaluateInto(q, sb);
    ASSERT_EQ(ra.status, rb.status) << what;
    ASSERT_EQ(ra.vertex_count, rb.vertex_count) << what;
    ASSERT_EQ(ra.simplex, rb.simplex) << what;
    ASSERT_EQ(ra.empty_orthants, rb.empty_orthants) << what;
    for (int k = 0; k < ra.vertex_count; ++k) {
      const auto u = static_cast<std::size_t>(k);
      ASSERT_EQ(ra.index[u], rb.index[u]) << what;
      ASSERT_EQ(Bits(ra.weight[u]), Bits(rb.weight[u])) << what;
    }
    ExpectSameBits(sa, sb, what + " EvaluateInto spectrum");
    if (a.status == InterpStatus::kOk) ExpectSameBits(sa, a.spectrum, what + " Into vs Evaluate");

    std::vector<double> pa(nb, -1.0);  // untouched unless kOk, as sb
    ASSERT_EQ(grown.SpectrumAt(q, pa), b.status) << what;
    ExpectSameBits(pa, sb, what + " SpectrumAt");
  }

  // The pipelined batch path over all queries at once.
  const auto d = static_cast<std::size_t>(fresh.dims());
  std::vector<double> flat;
  for (const Point& q : queries) flat.insert(flat.end(), q.begin(), q.end());
  ASSERT_EQ(flat.size(), queries.size() * d);
  std::vector<InterpStatus> st_a(queries.size()), st_b(queries.size());
  std::vector<double> sp_a(queries.size() * nb), sp_b(queries.size() * nb);
  grown.SpectraAt(flat, st_a, sp_a);
  fresh.SpectraAt(flat, st_b, sp_b);
  ASSERT_EQ(st_a, st_b) << where << " SpectraAt statuses";
  ExpectSameBits(sp_a, sp_b, where + " SpectraAt spectra");
}

// Points on a coarse lattice (many exact duplicates and distance ties), some on φ = 0 (where a
// mirrored copy coincides with its original) and some on θi = θo (reciprocity copies coincide).
std::vector<Point> TieHeavyPoints(std::size_t n, int dims, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> cell(0, 6);
  std::vector<Point> out;
  for (std::size_t i = 0; i < n; ++i) {
    Point p(static_cast<std::size_t>(dims));
    for (auto& x : p) x = 10.0 * cell(rng);
    if (dims == 3 && i % 7 == 0) p[2] = 0.0;
    if (dims == 3 && i % 11 == 0) p[1] = p[0];
    out.push_back(p);
  }
  return out;
}

// Queries at lattice points, halfway between them (equal distances to several points), and at
// random spots, some outside the data (empty orthants).
std::vector<Point> Queries(int dims, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> cell(0, 12);
  std::uniform_real_distribution<double> any(-5.0, 65.0);
  std::vector<Point> out;
  for (int i = 0; i < 60; ++i) {
    Point p(static_cast<std::size_t>(dims));
    for (auto& x : p) x = i % 3 == 2 ? any(rng) : 5.0 * cell(rng);
    out.push_back(p);
  }
  return out;
}

std::vector<Point> RandomPoints(std::size_t n, int dims, std::uint64_t seed) {
  std::vector<double> lo(static_cast<std::size_t>(dims), 0.0);
  std::vector<double> hi(static_cast<std::size_t>(dims), 60.0);
  return testing::RandomPoints(n, lo, hi, seed);
}

void AddPoint(SampleSet& set, const Point& p, const SpectrumFn& fn, std::int64_t id) {
  ASSERT_TRUE(set.Add(id, p, fn(p)).ok());
}

struct GrowCase {
  std::string name;
  int dims = 3;
  Options options;
  bool ties = false;
  std::size_t base = 0;   // samples in the first full build
  std::size_t added = 0;  // samples landing after it
  std::size_t burst = 1;  // samples per Extend
  std::size_t max_tail = 0;
};

void PrintTo(const GrowCase& c, std::ostream* os) {
  *os << c.name;
}

// Grows a set from `base` samples, extending the interpolator after every burst, and compares
// every intermediate interpolator with a fresh one. Returns how often a fold (tail_size() == 0
// after an Extend) happened and the largest tail seen.
void Grow(const GrowCase& c, std::size_t* folds, std::size_t* largest_tail) {
  const int bands = 5;
  const SpectrumFn fn = LinearSpectrum(c.dims, bands);
  const std::vector<Point> points = c.ties ? TieHeavyPoints(c.base + c.added, c.dims, 7)
                                           : RandomPoints(c.base + c.added, c.dims, 11);
  const std::vector<Point> queries = [&] {
    std::vector<Point> q = Queries(c.dims, 13);
    // Queries exactly at some samples, old and new: they sit on the splitting planes.
    for (std::size_t i = 0; i < points.size(); i += 17) q.push_back(points[i]);
    return q;
  }();

  auto set = std::make_shared<SampleSet>(c.dims, bands);
  for (std::size_t i = 0; i < c.base; ++i)
    AddPoint(*set, points[i], fn, 1000 + static_cast<std::int64_t>(i));
  std::shared_ptr<const SampleSet> current = set;
  auto made = OctantInterpolator::Create(current, c.options);
  ASSERT_TRUE(made.ok()) << made.status().ToString();
  std::unique_ptr<OctantInterpolator> interp = std::move(made).value();

  *folds = 0;
  *largest_tail = 0;
  std::size_t next = c.base;
  while (next < points.size()) {
    // The daemon's way: copy the published set (sharing its chunks), add, publish the copy.
    auto grown = std::make_shared<SampleSet>(*current);
    for (std::size_t k = 0; k < c.burst && next < points.size(); ++k, ++next) {
      AddPoint(*grown, points[next], fn, 1000 + static_cast<std::int64_t>(next));
    }
    auto extended = OctantInterpolator::Extend(*interp, grown, c.max_tail);
    ASSERT_TRUE(extended.ok()) << extended.status().ToString();
    auto fresh = OctantInterpolator::Create(grown, c.options);
    ASSERT_TRUE(fresh.ok()) << fresh.status().ToString();
    const OctantInterpolator& e = **extended;
    ASSERT_EQ(e.indexed_size() + e.tail_size(), grown->size());
    if (e.tail_size() == 0) ++*folds;
    *largest_tail = std::max(*largest_tail, e.tail_size());
    ExpectSameAnswers(e, **fresh, queries, c.name + " at " + std::to_string(grown->size()));
    if (::testing::Test::HasFatalFailure()) return;
    // The previous interpolator still answers over its own samples (snapshot semantics).
    ASSERT_EQ(interp->indexed_size() + interp->tail_size(), current->size());
    interp = std::move(extended).value();
    current = grown;
  }
}

class OctantExtendTest : public ::testing::TestWithParam<GrowCase> {};

TEST_P(OctantExtendTest, EveryAnswerEqualsAFreshBuild) {
  const GrowCase& c = GetParam();
  std::size_t folds = 0, largest = 0;
  Grow(c, &folds, &largest);
  if (HasFatalFailure()) return;
  // The extend path really ran (a tail was scanned) ...
  EXPECT_GT(largest, 0u);
  // ... and a tail past the bound was folded into a fresh tree.
  const std::size_t bound =
      c.max_tail > 0 ? c.max_tail : OctantInterpolator::DefaultMaxTail(c.base);
  if (c.added > bound + c.burst) {
    EXPECT_GT(folds, 0u);
  }
  EXPECT_LE(largest, bound);
}

Options Opt(bool mirror, bool reciprocity, std::vector<double> scale = {}) {
  Options o;
  o.mirror_phi = mirror;
  o.reciprocity = reciprocity;
  o.axis_scale = std::move(scale);
  return o;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, OctantExtendTest,
    ::testing::Values(
        GrowCase{"plain_one_by_one", 3, Opt(false, false), false, 40, 90, 1, 0},
        GrowCase{"mirror_one_by_one", 3, Opt(true, false), false, 40, 40, 1, 16},
        GrowCase{"reciprocity_bursts", 3, Opt(false, true), false, 30, 120, 9, 0},
        GrowCase{"both_bursts", 3, Opt(true, true, {1.0, 1.0, 0.5}), false, 50, 100, 7, 24},
        GrowCase{"ties_plain", 3, Opt(false, false), true, 30, 60, 1, 20},
        GrowCase{"ties_both_one_by_one", 3, Opt(true, true), true, 20, 50, 1, 12},
        GrowCase{"ties_mirror_bursts", 3, Opt(true, false), true, 25, 80, 5, 0},
        GrowCase{"four_d_one_by_one", 4, Opt(false, false), false, 60, 40, 1, 16},
        GrowCase{"four_d_ties_bursts", 4, Opt(false, false, {1, 0.5, 1, 0.5}), true, 40, 90, 6, 0},
        // From a single sample: at first every query but a few has an empty orthant.
        GrowCase{"from_one_sample", 3, Opt(true, true), false, 1, 70, 1, 0}),
    [](const ::testing::TestParamInfo<GrowCase>& param_info) { return param_info.param.name; });

TEST(OctantExtendTest, ExtendingTwiceFromTheSameBaseGivesIndependentInterpolators) {
  const SpectrumFn fn = LinearSpectrum(3, 3);
  const std::vector<Point> points = RandomPoints(120, 3, 5);
  auto base_set = std::make_shared<SampleSet>(3, 3);
  for (std::size_t i = 0; i < 100; ++i)
    AddPoint(*base_set, points[i], fn, static_cast<std::int64_t>(i));
  auto base = OctantInterpolator::Create(base_set, Opt(true, false)).value();
  auto a = std::make_shared<SampleSet>(*base_set);
  auto b = std::make_shared<SampleSet>(*base_set);
  for (std::size_t i = 100; i < 110; ++i) AddPoint(*a, points[i], fn, static_cast<std::int64_t>(i));
  for (std::size_t i = 110; i < 120; ++i) AddPoint(*b, points[i], fn, static_cast<std::int64_t>(i));
  auto ea = OctantInterpolator::Extend(*base, a).value();
  auto eb = OctantInterpolator::Extend(*base, b).value();
  const auto queries = Queries(3, 3);
  ExpectSameAnswers(*ea, *OctantInterpolator::Create(a, Opt(true, false)).value(), queries, "a");
  ExpectSameAnswers(*eb, *OctantInterpolator::Create(b, Opt(true, false)).value(), queries, "b");
  ExpectSameAnswers(*base, *OctantInterpolator::Create(base_set, Opt(true, false)).value(), queries,
                    "base");
  // Extending by nothing is allowed and answers as the base does.
  auto same = OctantInterpolator::Extend(*base, base_set).value();
  EXPECT_EQ(same->tail_size(), 0u);
  ExpectSameAnswers(*same, *base, queries, "by nothing");
}

TEST(OctantExtendTest, RejectsSetsThatDoNotContinueTheBase) {
  const SpectrumFn fn = LinearSpectrum(3, 2);
  const std::vector<Point> points = RandomPoints(20, 3, 9);
  auto set = std::make_shared<SampleSet>(3, 2);
  for (std::size_t i = 0; i < 10; ++i) AddPoint(*set, points[i], fn, static_cast<std::int64_t>(i));
  auto base = OctantInterpolator::Create(set).value();

  EXPECT_EQ(OctantInterpolator::Extend(*base, nullptr).status().code(),
            StatusCode::kInvalidArgument);
  auto shorter = std::make_shared<SampleSet>(3, 2);
  for (std::size_t i = 0; i < 5; ++i)
    AddPoint(*shorter, points[i], fn, static_cast<std::int64_t>(i));
  EXPECT_EQ(OctantInterpolator::Extend(*base, shorter).status().code(),
            StatusCode::kInvalidArgument);
  auto other_bands = std::make_shared<SampleSet>(3, 3);
  const SpectrumFn fn3 = LinearSpectrum(3, 3);
  for (std::size_t i = 0; i < 12; ++i)
    AddPoint(*other_bands, points[i], fn3, static_cast<std::int64_t>(i));
  EXPECT_EQ(OctantInterpolator::Extend(*base, other_bands).status().code(),
            StatusCode::kInvalidArgument);
  // Same size and shape but built separately, with another sample where the base's last one is.
  auto diverged = std::make_shared<SampleSet>(3, 2);
  for (std::size_t i = 0; i < 9; ++i)
    AddPoint(*diverged, points[i], fn, static_cast<std::int64_t>(i));
  AddPoint(*diverged, points[15], fn, 9);
  AddPoint(*diverged, points[10], fn, 10);
  const auto r = OctantInterpolator::Extend(*base, diverged);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("sample 9"), std::string::npos) << r.status().message();
  // A set rebuilt separately with the same samples continues the base just as well.
  auto rebuilt = std::make_shared<SampleSet>(3, 2);
  for (std::size_t i = 0; i < 12; ++i)
    AddPoint(*rebuilt, points[i], fn, static_cast<std::int64_t>(i));
  auto ok = OctantInterpolator::Extend(*base, rebuilt);
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  ExpectSameAnswers(**ok, *OctantInterpolator::Create(rebuilt).value(), Queries(3, 1), "rebuilt");
}

// Create searches with the grid shortcut where the cloud gets one (3D), the tree alone when asked
// or in 4D; an extension keeps its base's index and a fold builds the tree alone (it runs while a
// session records). Every combination answers exactly as the tree alone does.
TEST(OctantExtendTest, CreateUsesTheGridAndFoldsBuildTheTreeAlone) {
  const SpectrumFn fn = testing::AnalyticSpectrum(3);
  const std::vector<Point> points = testing::PaperGrid();
  auto set = std::make_shared<SampleSet>(3, static_cast<int>(fn(points[0]).size()));
  for (std::size_t i = 0; i < 1500; ++i)
    AddPoint(*set, points[i], fn, static_cast<std::int64_t>(i));
  const auto grid = OctantInterpolator::Create(set).value();
  const auto tree = OctantInterpolator::Create(set, {}, OctantInterpolator::Search::kTree).value();
  EXPECT_EQ(grid->search(), OctantInterpolator::Search::kGridThenTree);
  EXPECT_EQ(tree->search(), OctantInterpolator::Search::kTree);
  // Random queries over the rig's range (the grid answers most), some outside the data.
  const std::vector<Point> queries =
      testing::RandomPoints(400, {-2.0, -2.0, -2.0}, {92.0, 92.0, 182.0}, 77);
  ExpectSameAnswers(*grid, *tree, queries, "grid vs tree");

  auto grown = std::make_shared<SampleSet>(*set);
  for (std::size_t i = 1500; i < 1510; ++i)
    AddPoint(*grown, points[i], fn, static_cast<std::int64_t>(i));
  const auto extended = OctantInterpolator::Extend(*grid, grown).value();
  EXPECT_EQ(extended->tail_size(), 10u);
  EXPECT_EQ(extended->search(), OctantInterpolator::Search::kGridThenTree);
  const auto grown_tree =
      OctantInterpolator::Create(grown, {}, OctantInterpolator::Search::kTree).value();
  ExpectSameAnswers(*extended, *grown_tree, queries, "extended grid vs tree");

  auto folded_set = std::make_shared<SampleSet>(*grown);
  for (std::size_t i = 1510; i < points.size(); ++i)
    AddPoint(*folded_set, points[i], fn, static_cast<std::int64_t>(i));
  const auto folded = OctantInterpolator::Extend(*extended, folded_set).value();
  EXPECT_EQ(folded->tail_size(), 0u);
  EXPECT_EQ(folded->search(), OctantInterpolator::Search::kTree);
  ExpectSameAnswers(*folded, *OctantInterpolator::Create(folded_set).value(), queries,
                    "folded vs grid");

  // 4D clouds get no grid, whatever Create is asked.
  const SpectrumFn fn4 = LinearSpectrum(4, 3);
  auto set4 = std::make_shared<SampleSet>(4, 3);
  const std::vector<Point> points4 = RandomPoints(300, 4, 5);
  for (std::size_t i = 0; i < points4.size(); ++i)
    AddPoint(*set4, points4[i], fn4, static_cast<std::int64_t>(i));
  EXPECT_EQ(OctantInterpolator::Create(set4).value()->search(), OctantInterpolator::Search::kTree);
}

TEST(SampleSetChunksTest, CopiesShareStorageAndGrowIndependently) {
  const auto chunk = SampleSet::kChunkSamples;
  const std::size_t n = 2 * chunk + chunk / 2;  // two full chunks and a partial one
  SampleSet original(3, 2);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i);
    const std::vector<double> c = {x, x + 0.5, -x};
    const std::vector<double> v = {2 * x, 3 * x};
    ASSERT_TRUE(original.Add(static_cast<std::int64_t>(100 + i), c, v).ok());
  }
  SampleSet copy = original;
  for (std::size_t i = 0; i < n; ++i) EXPECT_TRUE(copy.SharesStorageWith(original, i)) << i;

  // The copy grows past the end of the partial chunk and into a new one.
  for (std::size_t i = n; i < n + chunk; ++i) {
    const double x = static_cast<double>(i);
    ASSERT_TRUE(copy.Add(static_cast<std::int64_t>(100 + i), std::vector<double>{x, x, x},
                         std::vector<double>{-x, -x})
                    .ok());
  }
  ASSERT_EQ(original.size(), n);
  ASSERT_EQ(copy.size(), n + chunk);
  // Full chunks are still shared; the partial one was copied before the first write.
  EXPECT_TRUE(copy.SharesStorageWith(original, 0));
  EXPECT_TRUE(copy.SharesStorageWith(original, 2 * chunk - 1));
  EXPECT_FALSE(copy.SharesStorageWith(original, 2 * chunk));
  for (std::size_t i = 0; i < n + chunk; ++i) {
    const double x = static_cast<double>(i);
    const SampleSet& s = i < n ? original : copy;
    EXPECT_EQ(s.id(i), static_cast<std::int64_t>(100 + i));
    if (i < n) {
      EXPECT_EQ(copy.id(i), original.id(i));
      EXPECT_EQ(s.coords(i)[1], x + 0.5);
      EXPECT_EQ(s.spectrum(i)[1], 3 * x);
      EXPECT_EQ(copy.spectrum(i)[0], original.spectrum(i)[0]);
    } else {
      EXPECT_EQ(s.coords(i)[2], x);
      EXPECT_EQ(s.spectrum(i)[0], -x);
    }
  }
  // The original can grow too, without disturbing the copy.
  ASSERT_TRUE(original.Add(7, std::vector<double>{1, 2, 3}, std::vector<double>{4, 5}).ok());
  EXPECT_EQ(original.id(n), 7);
  EXPECT_EQ(copy.id(n), static_cast<std::int64_t>(100 + n));
  EXPECT_EQ(original.spectrum(n)[1], 5);

  // A set nobody shares writes in place: samples already added keep their storage.
  SampleSet alone(3, 1);
  ASSERT_TRUE(alone.Add(1, std::vector<double>{1, 1, 1}, std::vector<double>{1}).ok());
  const double* first = alone.spectrum(0).data();
  ASSERT_TRUE(alone.Add(2, std::vector<double>{2, 2, 2}, std::vector<double>{2}).ok());
  EXPECT_EQ(alone.spectrum(0).data(), first);
}

}  // namespace
}  // namespace brdf::interp
