#include "core/interp/octant/octant.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <string>
#include <vector>

#include "core/interp/barycentric.h"
#include "core/interp/octant/cube.h"
#include "core/interp/search/kd_tree.h"
#include "core/interp/search/point_cloud.h"

namespace brdf::interp {

namespace {

// The search tree over the first `cloud.size() / images` samples and the cloud it points into.
// Immutable once built; shared by every interpolator extended from the one that built it.
struct SearchIndex {
  SearchIndex(PointCloud c, KdTree::Search search)
      : cloud(std::move(c)), tree(cloud, KdTree::Kernel::kBest, search) {}
  SearchIndex(const SearchIndex&) = delete;
  SearchIndex& operator=(const SearchIndex&) = delete;

  PointCloud cloud;  // before `tree`, which points into it
  KdTree tree;
};

}  // namespace

// Ranks: every rank below is a rank in the cloud BuildPointCloud would make of all `total`
// samples ("grown rank": image b of sample s has rank b · total + s). The tree's ranks are ranks
// in its own cloud of `indexed` samples (b · indexed + s) and are translated on the way out.
struct OctantInterpolator::Impl {
  Impl(std::shared_ptr<const SampleSet> s, Options o, std::shared_ptr<const SearchIndex> i,
       PointCloud t)
      : samples(std::move(s)),
        options(std::move(o)),
        index(std::move(i)),
        indexed(static_cast<std::uint32_t>(index->cloud.size() / ImageCount(options))),
        total(static_cast<std::uint32_t>(samples->size())),
        tail(std::move(t)) {
    const std::size_t m = total - indexed;
    tail_rank.resize(tail.size());
    for (std::size_t k = 0; k < tail.size(); ++k) {
      tail_rank[k] = static_cast<std::uint32_t>((k / m) * total + indexed + k % m);
    }
  }

  // The SampleSet index of a grown rank.
  std::uint32_t SampleOf(std::uint32_t rank) const {
    return tail.size() == 0 ? index->cloud.sample[rank] : rank % total;
  }
  // The unscaled coordinates of a grown rank.
  std::span<const double> PointOf(std::uint32_t rank) const {
    if (tail.size() == 0) return index->cloud.point(rank);
    const std::uint32_t image = rank / total;
    const std::uint32_t s = rank % total;
    if (s < indexed) return index->cloud.point(std::size_t{image} * indexed + s);
    return tail.point(std::size_t{image} * (total - indexed) + (s - indexed));
  }

  // Step 2: the tree's winners, then the tail's points against them (exact distance, then rank).
  template <int D>
  void ScanTail(const double* p, OrthantWinners& winners) const {
    constexpr int kOrthants = 1 << D;
    std::array<double, kOrthants> best;
    for (int o = 0; o < kOrthants; ++o) {
      const auto u = static_cast<std::size_t>(o);
      std::uint32_t& rank = winners.rank[u];
      if (rank == kNoPoint) {
        best[u] = std::numeric_limits<double>::infinity();
        continue;
      }
      best[u] = SquaredDistance<D>(winners.scaled[u], p);
      std::uint32_t image = 0;
      while (rank >= indexed) {
        rank -= indexed;
        image += total;
      }
      rank += image;
    }
    const double* x = tail.scaled.data();
    for (std::size_t k = 0; k < tail.size(); ++k, x += D) {
      const auto o = static_cast<std::size_t>(OrthantOf<D>(x, p));
      const double dist = SquaredDistance<D>(x, p);
      if (dist < best[o] || (dist == best[o] && tail_rank[k] < winners.rank[o])) {
        best[o] = dist;
        winners.rank[o] = tail_rank[k];
        winners.scaled[o] = x;
      }
    }
  }

  void Search(const double* p, OrthantWinners& winners) const {
    index->tree.NearestPerOrthant(p, winners);
    if (tail.size() == 0) return;
    if (tail.dims == 3) {
      ScanTail<3>(p, winners);
    } else {
      ScanTail<4>(p, winners);
    }
  }

  // Steps 1–4 up to the blend: the query in scaled space, the winners, the simplex and weights.
  // False (and `blend` untouched) for an invalid query. `prefetch_all`: start fetching every
  // winner's spectrum right after the search (for a blend that follows at once); otherwise only
  // the chosen vertices' spectra are fetched, once the simplex is known (for a blend that comes
  // one query later, SpectraAt).
  bool Blend(std::span<const double> query, OctantBlend& blend, bool prefetch_all = true) const {
    const int d = index->cloud.dims;
    if (!ValidQuery(query, d)) return false;
    std::array<double, kMaxDims> p{};
    index->cloud.ScaleQuery(query, p);
    OrthantWinners winners;
    Search(p.data(), winners);
    // Start fetching the winners' spectra now: the blend uses 4 or 5 of them, and the fetch (from
    // main memory, for large sets) overlaps with the choice of the simplex.
    const int orthants = 1 << d;
    if (prefetch_all) {
      for (int o = 0; o < orthants; ++o) {
        const std::uint32_t rank = winners.rank[static_cast<std::size_t>(o)];
        if (rank != kNoPoint) PrefetchSpectrum(samples->spectrum(SampleOf(rank)));
      }
    }
    blend = FindOctantBlendFast(winners, std::span(p.data(), static_cast<std::size_t>(d)), d);
    if (!prefetch_all && blend.status == InterpStatus::kOk) {
      for (int k = 0; k <= d; ++k) {
        PrefetchSpectrum(samples->spectrum(SampleOf(blend.rank[static_cast<std::size_t>(k)])));
      }
    }
    return true;
  }

  // BlendOctantSpectrum's numbers (BlendSpectra over the vertices in order) for a kOk blend whose
  // ranks are grown ranks and whose spectra Blend prefetched already.
  void BlendInto(const OctantBlend& blend, std::span<double> out) const {
    std::array<std::uint32_t, kMaxDims + 1> sample{};
    for (std::size_t k = 0; k <= static_cast<std::size_t>(index->cloud.dims); ++k) {
      sample[k] = SampleOf(blend.rank[k]);
    }
    BlendSamples(blend.weight.data(), sample.data(), out);
  }
  // The same for dims + 1 vertices given as weights and SampleSet indices.
  void BlendSamples(const double* weight, const std::uint32_t* sample,
                    std::span<double> out) const {
    const auto vertex_count = static_cast<std::size_t>(index->cloud.dims + 1);
    std::array<const double*, kMaxDims + 1> spectra{};
    for (std::size_t k = 0; k < vertex_count; ++k) spectra[k] = samples->spectrum(sample[k]).data();
    BlendSpectra(std::span(weight, vertex_count), std::span(spectra.data(), vertex_count), out);
  }

  // Batches: whether SpectraAt sorts n queries by cell (SpectraByCell): 3D, no tail, and a batch
  // of at least a quarter of a query per cell. Measured on the rig grid (8,448 cells), sorted
  // against query by query: 500 queries 4 % slower, 1,000 even, 2,000 13 % faster, 4,000 24 %.
  // The cells are the grid's when the tree has one (their queries then share list scans), else
  // the seed grid's (about two points per cell).
  bool SortsByCell(std::size_t n) const {
    return tail.size() == 0 && index->cloud.dims == 3 && n * 4 >= SortCells();
  }
  // The cells a batch is sorted by: the orthant grid's, or the seed grid's when there is none.
  std::size_t SortCells() const {
    const KdTree& tree = index->tree;
    return tree.grid().empty() ? tree.seed_cell_count() : tree.grid().cell_count();
  }

  // SpectraAt for a batch whose queries meet in cells, in three passes: (1) the queries scaled
  // and sorted by cell (a counting sort); (2) in cell order, the queries searched (with a grid,
  // those of a cell kCellLanes at a time with one scan of its list, KdTree::
  // NearestPerOrthantInCell; without one, one by one, the tree's paths and points still warm from
  // the previous query) and each one's simplex chosen, into one cache line per query written in
  // that order; (3) in query order, the spectra blended into the rows, which are written one
  // after another, each query's vertex spectra fetched a few queries ahead. Writing the rows in
  // cell order instead cost a cache miss per row (measured: about 0.1 µs per rig query).
  // The same answers as query by query, bit for bit.
  // Pass (1) of a sorted batch: the queries scaled and counting-sorted by cell.
  struct CellOrder {
    std::vector<std::uint32_t> start;  // cell c's queries are positions [start[c], start[c + 1])
    std::vector<std::uint32_t> slot;   // query i is the slot[i]-th in cell order
    std::vector<double> sorted;        // the scaled queries in cell order
    // Bucket `no_list` holds the queries outside every list; `unsearched` those answered without
    // a search (they keep kEmptyOctant): invalid ones, and those outside the points' box, where
    // some orthant is certainly empty (on the rig, most of the queries outside the grid).
    std::uint32_t no_list = 0;
    std::uint32_t unsearched = 0;
    bool Searched(std::size_t i) const { return slot[i] < start[unsearched]; }
  };
  CellOrder SortByCell(std::span<const double> queries) const {
    const KdTree& tree = index->tree;
    const bool lists = !tree.grid().empty();
    const std::size_t n = queries.size() / 3;
    const std::size_t cells = SortCells();
    CellOrder order;
    order.no_list = static_cast<std::uint32_t>(cells);
    order.unsearched = static_cast<std::uint32_t>(cells + 1);
    std::vector<double> scaled(3 * n);
    std::vector<std::uint32_t> bucket(n);
    std::vector<std::uint32_t>& start = order.start;
    start.assign(cells + 3, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::span<const double> query = queries.subspan(3 * i, 3);
      double* p = scaled.data() + 3 * i;
      bucket[i] = order.unsearched;
      if (ValidQuery(query, 3)) {
        index->cloud.ScaleQuery(query, std::span(p, 3));
        if (!tree.OutsideBox(p)) {
          const std::uint32_t cell = lists ? tree.ListedCell(p) : tree.SeedCell(p);
          bucket[i] = cell == OrthantGrid::kNoCell ? order.no_list : cell;
        }
      }
      ++start[bucket[i] + 1];
    }
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    order.slot.resize(n);
    order.sorted.resize(3 * n);
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      order.slot[i] = next[bucket[i]]++;
      std::copy_n(scaled.data() + 3 * i, 3, order.sorted.data() + 3 * std::size_t{order.slot[i]});
    }
    return order;
  }

  // Pass (2): in cell order, every searched query's blend, handed to keep(position in cell order,
  // blend). With a grid, the queries of a cell kCellLanes at a time with one scan of its list.
  template <typename Keep>
  void BlendInCellOrder(const CellOrder& order, Keep&& keep) const {
    const KdTree& tree = index->tree;
    const bool lists = !tree.grid().empty();
    const std::vector<std::uint32_t>& start = order.start;
    constexpr int kLanes = KdTree::kCellLanes;
    std::array<WinnerCube3, kLanes> cubes;
    std::array<const double*, kLanes> p{};
    for (std::uint32_t cell = 0; cell < order.no_list && lists; ++cell) {
      for (std::size_t first = start[cell]; first < start[cell + 1]; first += kLanes) {
        const int count = static_cast<int>(std::min<std::size_t>(kLanes, start[cell + 1] - first));
        for (int k = 0; k < count; ++k) p[k] = order.sorted.data() + 3 * (first + std::size_t(k));
        tree.NearestPerOrthantInCell(cell, p.data(), count, cubes.data());
        for (int k = 0; k < count; ++k) keep(first + k, FindOctantBlendFast(cubes[k], p[k]));
      }
    }
    OrthantWinners winners;
    for (std::size_t first = lists ? start[order.no_list] : 0; first < start[order.unsearched];
         ++first) {
      const double* q = order.sorted.data() + 3 * first;
      tree.NearestPerOrthant(q, winners);
      keep(first, FindOctantBlendFast(winners, std::span(q, 3), 3));
    }
  }

  // SpectraAt for a batch whose queries meet in cells, in three passes: (1) the queries scaled
  // and sorted by cell (a counting sort, SortByCell); (2) in cell order, the queries searched
  // (with a grid, those of a cell kCellLanes at a time with one scan of its list, KdTree::
  // NearestPerOrthantInCell; without one, one by one, the tree's paths and points still warm from
  // the previous query) and each one's simplex chosen, into one cache line per query written in
  // that order (BlendInCellOrder); (3) in query order, the spectra blended into the rows, which
  // are written one after another, each query's vertex spectra fetched a few queries ahead.
  // Writing the rows in cell order instead cost a cache miss per row (measured: about 0.1 µs per
  // rig query). The same answers as query by query, bit for bit.
  void SpectraByCell(std::span<const double> queries, std::span<InterpStatus> statuses,
                     std::span<double> spectra, std::size_t bands) const {
    const std::size_t n = statuses.size();
    const CellOrder order = SortByCell(queries);
    const std::vector<std::uint32_t>& slot = order.slot;
    std::vector<Vertices> answer(n);
    BlendInCellOrder(order,
                     [&](std::size_t at, const OctantBlend& blend) { answer[at] = Keep(blend); });
    sorted_queries.fetch_add(n, std::memory_order_relaxed);
    // (3) The spectra.
    constexpr std::size_t kAhead = 4;
    auto prefetch = [&](std::size_t i) {
      const Vertices& a = answer[slot[i]];
      if (a.status != InterpStatus::kOk) return;
      for (std::uint32_t s : a.sample) PrefetchSpectrum(samples->spectrum(s));
    };
    for (std::size_t i = 0; i < std::min(n, kAhead); ++i) prefetch(i);
    for (std::size_t i = 0; i < n; ++i) {
      if (i + 2 * kAhead < n) __builtin_prefetch(&answer[slot[i + 2 * kAhead]]);
      if (i + kAhead < n) prefetch(i + kAhead);
      const Vertices& a = answer[slot[i]];
      statuses[i] = a.status;
      const std::span<double> row = spectra.subspan(i * bands, bands);
      if (a.status == InterpStatus::kOk) {
        BlendSamples(a.weight.data(), a.sample.data(), Bands(row));
      } else {
        std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
      }
    }
  }

  // SpectraAt query by query, pipelined: query i is searched (its winners' spectra prefetched)
  // before query i − 1 is blended.
  void SpectraOneByOne(std::span<const double> queries, std::span<InterpStatus> statuses,
                       std::span<double> spectra, std::size_t bands) const {
    const auto d = static_cast<std::size_t>(index->cloud.dims);
    const std::size_t n = statuses.size();
    OctantBlend previous;
    for (std::size_t i = 0; i <= n; ++i) {
      OctantBlend blend;
      if (i < n) {
        if (!Blend(queries.subspan(i * d, d), blend, /*prefetch_all=*/false)) {
          blend.status = InterpStatus::kEmptyOctant;
        }
        statuses[i] = blend.status;
      }
      if (i > 0) {
        const std::span<double> row = spectra.subspan((i - 1) * bands, bands);
        if (previous.status == InterpStatus::kOk) {
          BlendInto(previous, Bands(row));
        } else {
          std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
        }
      }
      previous = blend;
    }
  }

  // What SpectraByCell keeps of a 3D blend for its spectrum: one cache line.
  struct alignas(64) Vertices {
    std::array<double, 4> weight;
    std::array<std::uint32_t, 4> sample;  // SampleSet indices
    InterpStatus status = InterpStatus::kEmptyOctant;
  };
  Vertices Keep(const OctantBlend& blend) const {
    Vertices v;
    v.status = blend.status;
    if (blend.status != InterpStatus::kOk) return v;
    for (std::size_t k = 0; k < 4; ++k) {
      v.weight[k] = blend.weight[k];
      v.sample[k] = SampleOf(blend.rank[k]);
    }
    return v;
  }

  // The complete answer of a blend (OctantInterpolation). With a tail, the grown cloud does not
  // exist as one array: the answer is assembled over a cloud of just the blend's vertices.
  Interpolation Answer(const OctantBlend& blend) const {
    if (tail.size() == 0) return OctantInterpolation(index->cloud, *samples, blend);
    PointCloud vertices;
    vertices.dims = index->cloud.dims;
    OctantBlend local = blend;
    if (blend.status == InterpStatus::kOk) {
      for (std::size_t k = 0; k <= static_cast<std::size_t>(vertices.dims); ++k) {
        const std::span<const double> x = PointOf(blend.rank[k]);
        vertices.coords.insert(vertices.coords.end(), x.begin(), x.end());
        vertices.sample.push_back(SampleOf(blend.rank[k]));
        local.rank[k] = static_cast<std::uint32_t>(k);
      }
    }
    return OctantInterpolation(vertices, *samples, local);
  }

  // The part of a caller's buffer that receives the spectrum (never more than bands() values).
  std::span<double> Bands(std::span<double> spectrum) const {
    return spectrum.first(std::min(spectrum.size(), static_cast<std::size_t>(samples->bands())));
  }

  std::shared_ptr<const SampleSet> samples;  // all `total` samples
  Options options;
  std::shared_ptr<const SearchIndex> index;  // samples [0, indexed)
  std::uint32_t indexed;
  std::uint32_t total;
  // The images of samples [indexed, total) (BuildPointCloudTail), and each one's grown rank.
  PointCloud tail;
  std::vector<std::uint32_t> tail_rank;
  // Queries answered by the sorted passes (sorted_queries()).
  mutable std::atomic<std::uint64_t> sorted_queries{0};
};

OctantInterpolator::OctantInterpolator(std::unique_ptr<const Impl> impl) : impl_(std::move(impl)) {}
OctantInterpolator::~OctantInterpolator() = default;

Result<std::unique_ptr<OctantInterpolator>> OctantInterpolator::Create(
    std::shared_ptr<const SampleSet> samples, const Options& options, Search search) {
  if (samples == nullptr) return InvalidArgument("octant interpolator: no sample set (null)");
  Result<PointCloud> cloud = BuildPointCloud(*samples, options);
  if (!cloud.ok()) return cloud.status().WithContext("octant interpolator");
  auto index = std::make_shared<const SearchIndex>(
      std::move(cloud).value(),
      search == Search::kTree ? KdTree::Search::kTree : KdTree::Search::kGridThenTree);
  PointCloud tail;
  tail.dims = samples->dims();
  auto impl =
      std::make_unique<const Impl>(std::move(samples), options, std::move(index), std::move(tail));
  return std::unique_ptr<OctantInterpolator>(new OctantInterpolator(std::move(impl)));
}

Result<std::unique_ptr<OctantInterpolator>> OctantInterpolator::Extend(
    const OctantInterpolator& base, std::shared_ptr<const SampleSet> grown, std::size_t max_tail) {
  const Impl& b = *base.impl_;
  if (grown == nullptr) return InvalidArgument("octant interpolator: no grown sample set (null)");
  const std::string where = "octant interpolator: extending an index over " +
                            std::to_string(b.total) + " samples to " +
                            std::to_string(grown->size()) + ": ";
  if (grown->dims() != b.samples->dims() || grown->bands() != b.samples->bands()) {
    return InvalidArgument(where + "the grown set has " + std::to_string(grown->dims()) +
                           " coordinates and " + std::to_string(grown->bands()) +
                           " bands, the index " + std::to_string(b.samples->dims()) + " and " +
                           std::to_string(b.samples->bands()) + "; build a new index instead");
  }
  if (grown->size() < b.total) {
    return InvalidArgument(where + "the grown set has fewer samples; build a new index instead");
  }
  // A cheap check that `grown` continues base's set (a full one would cost what Extend saves).
  const std::size_t last = b.total - 1;
  if (!grown->SharesStorageWith(*b.samples, last)) {
    const auto x = grown->coords(last);
    const auto y = b.samples->coords(last);
    if (grown->id(last) != b.samples->id(last) || !std::equal(x.begin(), x.end(), y.begin())) {
      return InvalidArgument(where + "sample " + std::to_string(last) +
                             " differs; the grown set must hold the index's samples first, in "
                             "the same order: build a new index instead");
    }
  }
  const std::size_t bound = max_tail > 0 ? max_tail : DefaultMaxTail(b.indexed);
  if (grown->size() - b.indexed > bound) return Create(std::move(grown), b.options, Search::kTree);

  Result<PointCloud> tail = BuildPointCloudTail(*grown, b.options, b.indexed);
  if (!tail.ok()) return tail.status().WithContext("octant interpolator");
  auto impl =
      std::make_unique<const Impl>(std::move(grown), b.options, b.index, std::move(tail).value());
  return std::unique_ptr<OctantInterpolator>(new OctantInterpolator(std::move(impl)));
}

std::size_t OctantInterpolator::DefaultMaxTail(std::size_t indexed) {
  return std::max<std::size_t>(32, indexed / 256);
}

int OctantInterpolator::dims() const {
  return impl_->index->cloud.dims;
}

OctantInterpolator::Search OctantInterpolator::search() const {
  return impl_->index->tree.grid().empty() ? Search::kTree : Search::kGridThenTree;
}

int OctantInterpolator::bands() const {
  return impl_->samples->bands();
}

const Options& OctantInterpolator::options() const {
  return impl_->options;
}

std::size_t OctantInterpolator::indexed_size() const {
  return impl_->indexed;
}

std::size_t OctantInterpolator::tail_size() const {
  return impl_->total - impl_->indexed;
}

// The tree shared with the index this one was extended from is counted here too: whichever is
// kept holds it.
std::size_t OctantInterpolator::HeapBytes() const {
  const Impl& i = *impl_;
  return sizeof(Impl) + sizeof(SearchIndex) + i.index->cloud.HeapBytes() +
         i.index->tree.HeapBytes() + i.tail.HeapBytes() +
         i.tail_rank.capacity() * sizeof(std::uint32_t);
}

Interpolation OctantInterpolator::Evaluate(std::span<const double> query) const {
  OctantBlend blend;
  if (!impl_->Blend(query, blend)) {
    return InvalidQueryAnswer(Method::kOctant, InterpStatus::kEmptyOctant, query, dims());
  }
  return impl_->Answer(blend);
}

void OctantInterpolator::EvaluateEach(std::span<const double> queries,
                                      const TakeAnswer& take) const {
  const auto d = static_cast<std::size_t>(dims());
  const std::size_t n = queries.size() / d;
  const Impl& impl = *impl_;
  // Windows bound the memory (the sort's ~100 bytes and one blend of ~80 bytes per query); a
  // window too short to sort goes query by query.
  constexpr std::size_t kWindow = std::size_t{1} << 16;
  for (std::size_t first = 0; first < n; first += kWindow) {
    const std::size_t count = std::min(kWindow, n - first);
    const std::span<const double> window = queries.subspan(first * d, count * d);
    if (!impl.SortsByCell(count)) {
      for (std::size_t i = 0; i < count; ++i) {
        if (!take(first + i, Evaluate(window.subspan(i * d, d)))) return;
      }
      continue;
    }
    const Impl::CellOrder order = impl.SortByCell(window);
    std::vector<OctantBlend> blends(count);
    impl.BlendInCellOrder(order,
                          [&](std::size_t at, const OctantBlend& blend) { blends[at] = blend; });
    impl.sorted_queries.fetch_add(count, std::memory_order_relaxed);
    for (std::size_t i = 0; i < count; ++i) {
      // Unsearched queries (invalid, or outside the points' box) get Evaluate's own answer, whose
      // detail names the empty orthants.
      Interpolation answer = order.Searched(i) ? impl.Answer(blends[order.slot[i]])
                                               : Evaluate(window.subspan(i * d, d));
      if (!take(first + i, std::move(answer))) return;
    }
  }
}

std::uint64_t OctantInterpolator::sorted_queries() const {
  return impl_->sorted_queries.load(std::memory_order_relaxed);
}

InterpStatus OctantInterpolator::SpectrumAt(std::span<const double> query,
                                            std::span<double> spectrum) const {
  OctantBlend blend;
  if (!impl_->Blend(query, blend)) return InterpStatus::kEmptyOctant;
  if (blend.status == InterpStatus::kOk) {
    impl_->BlendInto(blend, impl_->Bands(spectrum));
  }
  return blend.status;
}

void OctantInterpolator::SpectraAt(std::span<const double> queries,
                                   std::span<InterpStatus> statuses,
                                   std::span<double> spectra) const {
  const std::size_t n = statuses.size();
  if (n == 0) return;
  const auto d = static_cast<std::size_t>(dims());
  const std::size_t bands = spectra.size() / n;
  const Impl& impl = *impl_;
  // Sorted batches go by windows, which bounds the sort's memory (about 100 bytes per query); a
  // last window too short to sort goes query by query.
  constexpr std::size_t kWindow = std::size_t{1} << 16;
  std::size_t first = 0;
  for (; first < n && impl.SortsByCell(std::min(kWindow, n - first)); first += kWindow) {
    const std::size_t count = std::min(kWindow, n - first);
    impl.SpectraByCell(queries.subspan(first * d, count * d), statuses.subspan(first, count),
                       spectra.subspan(first * bands, count * bands), bands);
  }
  if (first >= n) return;
  impl.SpectraOneByOne(queries.subspan(first * d), statuses.subspan(first),
                       spectra.subspan(first * bands), bands);
}

OctantResult OctantInterpolator::EvaluateInto(std::span<const double> query,
                                              std::span<double> spectrum) const {
  OctantResult out;
  OctantBlend blend;
  if (!impl_->Blend(query, blend)) {
    out.empty_orthants = (1u << (1 << dims())) - 1u;  // every orthant
    return out;
  }
  out.status = blend.status;
  out.empty_orthants = blend.empty_orthants;
  if (blend.status != InterpStatus::kOk) return out;
  impl_->BlendInto(blend, impl_->Bands(spectrum));
  out.simplex = blend.simplex;
  out.vertex_count = dims() + 1;
  for (std::size_t k = 0; k < static_cast<std::size_t>(out.vertex_count); ++k) {
    out.index[k] = impl_->SampleOf(blend.rank[k]);
    out.weight[k] = blend.weight[k];
  }
  return out;
}

Result<std::unique_ptr<Interpolator>> MakeOctantInterpolator(
    std::shared_ptr<const SampleSet> samples, const Options& options) {
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<OctantInterpolator> r,
                        OctantInterpolator::Create(std::move(samples), options));
  return std::unique_ptr<Interpolator>(std::move(r));
}

}  // namespace brdf::interp
