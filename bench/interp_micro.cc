// Micro-benchmarks of the interpolation index and blend (Google Benchmark), on the data sets of
// bench/run.sh: the paper's rig grid (2,153 points), 50,000 uniform random points in
// [0,90)×[0,90)×[0,360), and a 4D anisotropic set; 101-band analytic spectra (brdf-interp synth's
// data: the same generators, the same seeds). Queries: random rig poses for the rig grid (as
// compare.py's), uniform random in the data's box for the others; random order, 4,096 cycled.
//
// Figures: items_per_second is queries (or builds, or blends) per second, one thread.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/interp/barycentric.h"
#include "core/interp/octant/cube.h"
#include "core/interp/octant/octant.h"
#include "core/interp/search/kd_tree.h"
#include "core/interp/search/orthant_grid.h"
#include "core/interp/search/point_cloud.h"
#include "core/wavelength_grid.h"
#include "tools/brdf-interp/synthetic_samples.h"

namespace brdf::interp {
namespace {

constexpr std::size_t kQueries = 4096;

struct DataSet {
  std::string name;
  std::shared_ptr<SampleSet> samples;
  PointCloud cloud;
  std::vector<double> queries;  // kQueries × dims, already scaled (scale 1)
};

// n random rig poses, as compare.py's rig queries: α in [0, 70], β in [−175, 180], δ in
// [0, 146.25] degrees, converted to (θi, θo, φ) with geometry.md's closed forms; 3 per pose.
std::vector<double> RigPoses(std::size_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  constexpr double kRad = 3.14159265358979323846 / 180.0;
  std::vector<double> out;
  while (out.size() < n * 3) {
    const double a = 70.0 * u(rng) * kRad;
    const double b = (-175.0 + 355.0 * u(rng)) * kRad;
    const double dl = 146.25 * u(rng) * kRad;
    const double ci = std::cos(a) * std::cos(b);
    const double co = std::cos(a) * std::cos(b - dl);
    const double ti = std::acos(std::clamp(ci, -1.0, 1.0)) / kRad;
    const double to = std::acos(std::clamp(co, -1.0, 1.0)) / kRad;
    if (ti > 89.999 || to > 89.999) continue;
    double phi = 0.0;
    if (ti > 1e-7 && to > 1e-7) {
      const double c = (std::cos(dl) - ci * co) / (std::sin(ti * kRad) * std::sin(to * kRad));
      phi = std::acos(std::clamp(c, -1.0, 1.0)) / kRad;
    }
    out.insert(out.end(), {ti, to, phi});
  }
  return out;
}

const DataSet& Data(const std::string& name) {
  static std::map<std::string, std::unique_ptr<DataSet>> sets;
  auto& slot = sets[name];
  if (slot) return *slot;
  interp_tool::SyntheticPoints points;
  std::vector<double> hi;
  if (name == "rig" || name == "rig_mirror") {
    points = interp_tool::PaperGridPoints().value();
    hi = {90, 90, 180};
  } else if (name == "random50k") {
    points = interp_tool::RandomPoints(50000, 12, 3);
    hi = {90, 90, 360};
  } else {
    points = interp_tool::RandomPoints(4000, 13, 4);
    hi = {90, 360, 90, 360};
  }
  slot = std::make_unique<DataSet>();
  slot->name = name;
  slot->samples = interp_tool::SyntheticSamples(points, WavelengthGrid::Pr650());
  Options options;
  options.mirror_phi = name == "rig_mirror";  // the cloud doubles: (θi, θo, −φ) copies
  slot->cloud = BuildPointCloud(*slot->samples, options).value();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (name == "rig" || name == "rig_mirror") {
    slot->queries = RigPoses(kQueries, rng);
    return *slot;
  }
  slot->queries.resize(kQueries * hi.size());
  for (std::size_t i = 0; i < slot->queries.size(); ++i) {
    slot->queries[i] = hi[i % hi.size()] * u(rng);
  }
  return *slot;
}

const char* const kSets[] = {"rig", "random50k", "aniso4d"};

void BM_KdTreeBuild(benchmark::State& state, std::string set, KdTree::Kernel kernel) {
  const DataSet& data = Data(set);
  for (auto _ : state) {
    KdTree tree(data.cloud, kernel, KdTree::Search::kTree);
    benchmark::DoNotOptimize(tree.node_count());
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["points"] = static_cast<double>(data.cloud.size());
}

// The grid shortcut of the octant search (core/interp/search/orthant_grid.h): build time (tree and
// grid), size, and how many of the benchmark's queries it answers (the rest walk the tree).
void BM_GridBuild(benchmark::State& state, std::string set) {
  const DataSet& data = Data(set);
  // What a user of the shortcut pays: the tree and its grid.
  for (auto _ : state) {
    KdTree tree(data.cloud, KdTree::Kernel::kBest, KdTree::Search::kGridThenTree);
    benchmark::DoNotOptimize(tree.grid().entries());
  }
  const KdTree tree(data.cloud, KdTree::Kernel::kBest, KdTree::Search::kGridThenTree);
  const OrthantGrid& grid = tree.grid();
  const auto d = static_cast<std::size_t>(data.cloud.dims);
  std::size_t hits = 0;
  for (std::size_t i = 0; i < kQueries; ++i) {
    std::uint32_t begin = 0, count = 0, need = 0;
    const double* q = data.queries.data() + i * d;
    hits += d == 3 ? grid.Find<3>(q, begin, count, need) : grid.Find<4>(q, begin, count, need);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["cells"] = static_cast<double>(grid.cell_count());
  state.counters["listed%"] =
      100.0 * static_cast<double>(grid.listed_cells()) / static_cast<double>(grid.cell_count());
  state.counters["per_list"] =
      static_cast<double>(grid.entries()) / static_cast<double>(grid.listed_cells());
  state.counters["MB"] = static_cast<double>(grid.bytes()) / 1e6;
  state.counters["hit%"] = 100.0 * static_cast<double>(hits) / kQueries;
  state.counters["no_hole"] = static_cast<double>(grid.unlisted()[0]);
  state.counters["no_far"] = static_cast<double>(grid.unlisted()[1]);
  state.counters["no_long"] = static_cast<double>(grid.unlisted()[2]);
}

// The search on the queries the grid answers alone (its lists' scan, no tree). `hot`: the first
// 16 of them only, whose lists and points stay in L1 (what the scan costs without cache misses).
void BM_GridHits(benchmark::State& state, std::string set, bool hot) {
  const DataSet& data = Data(set);
  const KdTree tree(data.cloud, KdTree::Kernel::kBest, KdTree::Search::kGridThenTree);
  const auto d = static_cast<std::size_t>(data.cloud.dims);
  std::vector<double> hits;
  for (std::size_t i = 0; i < kQueries; ++i) {
    std::uint32_t begin = 0, count = 0, need = 0;
    const double* q = data.queries.data() + i * d;
    if (d == 3 ? tree.grid().Find<3>(q, begin, count, need)
               : tree.grid().Find<4>(q, begin, count, need)) {
      hits.insert(hits.end(), q, q + d);
    }
  }
  if (hits.empty()) {
    state.SkipWithError("no query inside a listed cell");
    return;
  }
  const std::size_t n = hot ? std::min<std::size_t>(16, hits.size() / d) : hits.size() / d;
  OrthantWinners winners;
  std::size_t i = 0;
  for (auto _ : state) {
    tree.NearestPerOrthant(hits.data() + i * d, winners);
    benchmark::DoNotOptimize(winners.rank[0]);
    i = (i + 1) % n;
  }
  state.SetItemsProcessed(state.iterations());
}

// The search as a large batch runs it (OctantInterpolator::SpectraAt): 50,000 random rig poses
// grouped by grid cell, the queries of a cell up to `lanes` at a time through
// KdTree::NearestPerOrthantInCell (lanes 1: one list scan per query, as NearestPerOrthant's grid
// path). Only the queries the grid answers; items = queries. Counter: queries per call.
void BM_CellGroups(benchmark::State& state, KdTree::Kernel kernel, int lanes) {
  const DataSet& data = Data("rig");
  const KdTree tree(data.cloud, kernel, KdTree::Search::kGridThenTree);
  std::mt19937_64 rng(11);
  const std::vector<double> poses = RigPoses(50000, rng);
  std::map<std::uint32_t, std::vector<const double*>> by_cell;
  for (std::size_t i = 0; i < poses.size(); i += 3) {
    const std::uint32_t cell = tree.ListedCell(poses.data() + i);
    if (cell != OrthantGrid::kNoCell) by_cell[cell].push_back(poses.data() + i);
  }
  struct Call {
    std::uint32_t cell;
    const double* const* queries;
    int count;
  };
  std::vector<Call> calls;
  std::size_t queries = 0;
  for (const auto& [cell, list] : by_cell) {
    for (std::size_t first = 0; first < list.size(); first += static_cast<std::size_t>(lanes)) {
      const int count = static_cast<int>(std::min<std::size_t>(lanes, list.size() - first));
      calls.push_back({cell, list.data() + first, count});
      queries += static_cast<std::size_t>(count);
    }
  }
  std::array<WinnerCube3, KdTree::kCellLanes> cubes;
  for (auto _ : state) {
    for (const Call& call : calls) {
      tree.NearestPerOrthantInCell(call.cell, call.queries, call.count, cubes.data());
      benchmark::DoNotOptimize(cubes[0].rank[0]);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(queries));
  state.counters["per_call"] = static_cast<double>(queries) / static_cast<double>(calls.size());
  state.SetLabel(KdTree::KernelName(tree.kernel()));
}

void BM_OrthantSearch(benchmark::State& state, std::string set, KdTree::Kernel kernel,
                      KdTree::Search search) {
  const DataSet& data = Data(set);
  const KdTree tree(data.cloud, kernel, search);
  const auto d = static_cast<std::size_t>(data.cloud.dims);
  OrthantWinners winners;
  std::size_t i = 0;
  for (auto _ : state) {
    tree.NearestPerOrthant(data.queries.data() + i * d, winners);
    benchmark::DoNotOptimize(winners.rank[0]);
    i = (i + 1) % kQueries;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(KdTree::KernelName(tree.kernel()) + std::string(", leaf ") +
                 std::to_string(tree.leaf_size()) +
                 (search == KdTree::Search::kTree ? ", tree only" : ", grid then tree"));
}

void BM_NearestSearch(benchmark::State& state, std::string set) {
  const DataSet& data = Data(set);
  const KdTree tree(data.cloud);
  const auto d = static_cast<std::size_t>(data.cloud.dims);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tree.Nearest(data.queries.data() + i * d));
    i = (i + 1) % kQueries;
  }
  state.SetItemsProcessed(state.iterations());
}

// Steps 3–4 on real winners: the first enclosing simplex and its barycentric weights.
void BM_FindBlend(benchmark::State& state, std::string set, bool fast,
                  BlendKernel kernel = BlendKernel::kBest) {
  const DataSet& data = Data(set);
  const KdTree tree(data.cloud);
  const auto d = static_cast<std::size_t>(data.cloud.dims);
  std::vector<OrthantWinners> winners(kQueries);
  for (std::size_t i = 0; i < kQueries; ++i) {
    tree.NearestPerOrthant(data.queries.data() + i * d, winners[i]);
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const std::span<const double> q(data.queries.data() + i * d, d);
    const OctantBlend blend = fast ? FindOctantBlendFast(winners[i], q, data.cloud.dims, kernel)
                                   : FindOctantBlend(winners[i], q, data.cloud.dims);
    benchmark::DoNotOptimize(blend.weight[0]);
    i = (i + 1) % kQueries;
  }
  state.SetItemsProcessed(state.iterations());
}

// The spectral blend alone: 4 (3D) or 5 (4D) vertex spectra of 101 bands, scattered in the set.
void BM_BlendSpectra(benchmark::State& state, std::string set) {
  const DataSet& data = Data(set);
  const SampleSet& s = *data.samples;
  const auto vertices = static_cast<std::size_t>(s.dims() + 1);
  std::mt19937_64 rng(3);
  std::vector<std::array<const double*, kMaxSimplexVertices>> picks(kQueries);
  for (auto& p : picks) {
    for (std::size_t k = 0; k < vertices; ++k) p[k] = s.spectrum(rng() % s.size()).data();
  }
  const std::array<double, kMaxSimplexVertices> weights = {0.1, 0.2, 0.3, 0.25, 0.15};
  std::vector<double> out(static_cast<std::size_t>(s.bands()));
  std::size_t i = 0;
  for (auto _ : state) {
    BlendSpectra(std::span(weights.data(), vertices), std::span(picks[i].data(), vertices), out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
    i = (i + 1) % kQueries;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(vertices) + " vertices × " + std::to_string(s.bands()) + " bands");
}

// One query end to end: the fast path (spectrum only) and the full answer with provenance.
void BM_OctantQuery(benchmark::State& state, std::string set, bool full) {
  const DataSet& data = Data(set);
  const auto interp = OctantInterpolator::Create(data.samples).value();
  const auto d = static_cast<std::size_t>(data.cloud.dims);
  std::vector<double> out(static_cast<std::size_t>(data.samples->bands()));
  std::size_t i = 0;
  for (auto _ : state) {
    const std::span<const double> q(data.queries.data() + i * d, d);
    if (full) {
      benchmark::DoNotOptimize(interp->Evaluate(q));
    } else {
      benchmark::DoNotOptimize(interp->SpectrumAt(q, out));
    }
    i = (i + 1) % kQueries;
  }
  state.SetItemsProcessed(state.iterations());
}

void RegisterAll() {
  const std::pair<KdTree::Kernel, const char*> kernels[] = {
      {KdTree::Kernel::kAvx512, "avx512"},
      {KdTree::Kernel::kAvx2, "avx2"},
      {KdTree::Kernel::kScalar, "scalar"},
  };
  for (const char* set : kSets) {
    for (const auto& [kernel, name] : kernels) {
      if (!KdTree::Supported(kernel)) continue;
      benchmark::RegisterBenchmark((std::string("KdTreeBuild/") + set + "/" + name).c_str(),
                                   [set = std::string(set), kernel = kernel](benchmark::State& s) {
                                     BM_KdTreeBuild(s, set, kernel);
                                   });
    }
  }
  for (const char* set : kSets) {
    for (const auto& [kernel, name] : kernels) {
      if (!KdTree::Supported(kernel)) continue;
      for (const auto search : {KdTree::Search::kGridThenTree, KdTree::Search::kTree}) {
        const char* how = search == KdTree::Search::kTree ? "/tree" : "";
        benchmark::RegisterBenchmark(
            (std::string("OrthantSearch/") + set + "/" + name + how).c_str(),
            [set = std::string(set), kernel = kernel, search](benchmark::State& s) {
              BM_OrthantSearch(s, set, kernel, search);
            });
      }
    }
  }
  for (const char* set : {"rig", "rig_mirror", "random50k", "aniso4d"}) {
    benchmark::RegisterBenchmark(
        (std::string("GridBuild/") + set).c_str(),
        [set = std::string(set)](benchmark::State& s) { BM_GridBuild(s, set); });
  }
  // Only the rig sets get a grid (OrthantGrid::Options::max_points, 3D only): the others have no
  // list to scan.
  for (const char* set : {"rig", "rig_mirror"}) {
    benchmark::RegisterBenchmark(
        (std::string("GridHits/") + set).c_str(),
        [set = std::string(set)](benchmark::State& s) { BM_GridHits(s, set, false); });
  }
  benchmark::RegisterBenchmark("GridHitsHot/rig",
                               [](benchmark::State& s) { BM_GridHits(s, "rig", true); });
  for (const auto& [kernel, name] : kernels) {
    if (!KdTree::Supported(kernel)) continue;
    for (int lanes : {1, KdTree::kCellLanes}) {
      benchmark::RegisterBenchmark(
          ("CellGroups/rig/" + std::string(name) + "/lanes" + std::to_string(lanes)).c_str(),
          [kernel = kernel, lanes](benchmark::State& s) { BM_CellGroups(s, kernel, lanes); });
    }
  }
  for (const char* set : kSets) {
    benchmark::RegisterBenchmark(
        (std::string("NearestSearch/") + set).c_str(),
        [set = std::string(set)](benchmark::State& s) { BM_NearestSearch(s, set); });
  }
  for (const char* set : kSets) {
    benchmark::RegisterBenchmark(
        (std::string("FindBlend/") + set).c_str(),
        [set = std::string(set)](benchmark::State& s) { BM_FindBlend(s, set, false); });
    benchmark::RegisterBenchmark(
        (std::string("FindBlend/") + set + "/fast").c_str(),
        [set = std::string(set)](benchmark::State& s) { BM_FindBlend(s, set, true); });
  }
  // The 3D vector kernels side by side (FindBlend/rig/fast runs the widest the CPU has).
  for (BlendKernel kernel : {BlendKernel::kAvx2, BlendKernel::kAvx512}) {
    if (!BlendKernelSupported(kernel)) continue;
    const std::string name = kernel == BlendKernel::kAvx2 ? "avx2" : "avx512";
    benchmark::RegisterBenchmark(("FindBlend/rig/" + name).c_str(), [kernel](benchmark::State& s) {
      BM_FindBlend(s, "rig", true, kernel);
    });
  }
  for (const char* set : {"rig", "aniso4d"}) {
    benchmark::RegisterBenchmark(
        (std::string("BlendSpectra/") + set).c_str(),
        [set = std::string(set)](benchmark::State& s) { BM_BlendSpectra(s, set); });
  }
  for (const char* set : kSets) {
    for (bool full : {false, true}) {
      benchmark::RegisterBenchmark(
          (std::string("OctantQuery/") + set + (full ? "/Evaluate" : "/SpectrumAt")).c_str(),
          [set = std::string(set), full](benchmark::State& s) { BM_OctantQuery(s, set, full); });
    }
  }
}

}  // namespace
}  // namespace brdf::interp

int main(int argc, char** argv) {
  brdf::interp::RegisterAll();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
