#include "core/interp/search/kd_tree.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/interp/search/kd_tree_cells.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define BRDF_KD_X86 1
#include <immintrin.h>
#endif

namespace brdf::interp {
namespace {

// Lower bounds are shrunk by this factor before pruning. They are already never above the
// computed distance of a point in the box (monotone rounded operations); the margin also covers
// a different summation order and fused multiply-adds in the bound itself.
constexpr double kBoundShrink = 1.0 - 1e-12;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Extra coordinates after the last point, so that an 8-wide load at a leaf's last point stays
// inside the arrays (the lanes past the leaf's end are masked out).
constexpr std::size_t kPadding = 8;

// max(a, b) without a branch (the compiler turns `a > b ? a : b` followed by a multiply into a
// jump; the bound's three of them per box were the search's worst-predicted branches).
inline double Max(double a, double b) {
#ifdef BRDF_KD_X86
  return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(a), _mm_set_sd(b)));
#else
  return a > b ? a : b;
#endif
}

// Which sides of the query a box spans, as a pattern index `lt | ge << D`: bit j of lt is set
// when the box has points with x_j < q_j (the − side of axis j), bit j of ge when it has points
// with x_j >= q_j (the + side). kReach<D>[pattern] is the set of orthants the box reaches (bit o
// for orthant o): those whose side on every axis the box spans.
template <int D>
constexpr std::array<std::uint16_t, 1 << (2 * D)> MakeReach() {
  std::array<std::uint16_t, 1 << (2 * D)> reach{};
  for (int pattern = 0; pattern < (1 << (2 * D)); ++pattern) {
    const int lt = pattern & ((1 << D) - 1), ge = pattern >> D;
    unsigned mask = 0;
    for (int o = 0; o < (1 << D); ++o) {
      bool in = true;
      for (int j = 0; j < D; ++j) in = in && (((o >> j) & 1) ? ((ge >> j) & 1) : ((lt >> j) & 1));
      if (in) mask |= 1u << o;
    }
    reach[static_cast<std::size_t>(pattern)] = static_cast<std::uint16_t>(mask);
  }
  return reach;
}
template <int D>
constexpr std::array<std::uint16_t, 1 << (2 * D)> kReach = MakeReach<D>();

}  // namespace

struct KdTree::OrthantBest {
  std::array<double, 4> q;              // the query (scaled)
  std::array<double, kMaxOrthants> d2;  // per orthant: best squared distance so far
  std::array<std::uint32_t, kMaxOrthants> rank;
  std::array<std::uint32_t, kMaxOrthants> pos;  // the best point's position in tree order

  // No best yet in any orthant. Empty orthants keep position kNoPoint, which no point has (the
  // AVX-512 kernels compare positions).
  void Clear() {
    d2.fill(kInf);
    rank.fill(kNoPoint);
    pos.fill(kNoPoint);
  }

  // The orthants whose best is at least `bound` (bit o for orthant o): those a box at that
  // distance could still improve.
  template <int D>
  unsigned Open(double bound) const {
#ifdef BRDF_KD_X86
    const __m128d b = _mm_set1_pd(bound);
    unsigned mask = 0;
#pragma GCC unroll 8
    for (int o = 0; o < (1 << D); o += 2) {
      const __m128d le = _mm_cmple_pd(b, _mm_loadu_pd(d2.data() + o));
      mask |= static_cast<unsigned>(_mm_movemask_pd(le)) << o;
    }
    return mask;
#else
    unsigned mask = 0;
    for (int o = 0; o < (1 << D); ++o) mask |= static_cast<unsigned>(bound <= d2[o]) << o;
    return mask;
#endif
  }

  // The exact rule of the brute-force scan: nearer wins; at the same distance, the lower rank.
  // Without a branch: whether a candidate wins is a coin toss the predictor would lose.
  bool Offer(std::size_t o, double dist2, std::uint32_t r, std::uint32_t at) {
    const double bd = d2[o];
    const std::uint32_t br = rank[o];
    const bool better = (dist2 < bd) | ((dist2 == bd) & (r < br));
    const std::uint64_t m = std::uint64_t{0} - static_cast<std::uint64_t>(better);
    const auto m32 = static_cast<std::uint32_t>(m);
    d2[o] = std::bit_cast<double>((std::bit_cast<std::uint64_t>(dist2) & m) |
                                  (std::bit_cast<std::uint64_t>(bd) & ~m));
    rank[o] = (r & m32) | (br & ~m32);
    pos[o] = (at & m32) | (pos[o] & ~m32);
    return better;
  }
};

struct KdTree::NearestBest {
  double d2 = kInf;
  std::uint32_t rank = kNoPoint;
};

#ifdef BRDF_KD_X86
// The per-orthant bests of a search held in AVX2 registers, for the AVX2 kernels: orthants
// 4r … 4r + 3 in register r (squared distances, and tree positions widened to 64 bits; 2 + 2
// registers in 3D, 4 + 4 in 4D). A lane's best is picked with a cross-lane permute (the orthant's
// low two bits) and blends (its higher bits): a handful of one-cycle instructions where
// vgatherqpd, which Zen 3 runs as many micro-ops, sat on the critical path of every 4 points.
// The memory copy (OrthantBest) stays the exact record; the registers follow every update.
template <int D>
struct Avx2Bests {
  static constexpr int kRegs = (1 << D) / 4;
  __m256d d2[kRegs];
  __m256i pos[kRegs];

  __attribute__((target("avx2"), always_inline)) inline void Load(const KdTree::OrthantBest& best) {
    for (int r = 0; r < kRegs; ++r) {
      d2[r] = _mm256_loadu_pd(best.d2.data() + 4 * r);
      pos[r] = _mm256_cvtepu32_epi64(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(best.pos.data() + 4 * r)));
    }
  }

  // Per lane, the orthant number (bit j from plus[j], the lane's x_j >= q_j mask).
  __attribute__((target("avx2"), always_inline)) static inline __m256i Code(const __m256d* plus) {
    __m256i code = _mm256_and_si256(_mm256_castpd_si256(plus[0]), _mm256_set1_epi64x(1));
    for (int j = 1; j < D; ++j) {
      code = _mm256_or_si256(
          code, _mm256_and_si256(_mm256_castpd_si256(plus[j]), _mm256_set1_epi64x(1 << j)));
    }
    return code;
  }

  // The lanes (bit k for lane k) whose point is nearer than its orthant's best, or as near but
  // not that very point (a best met again: the exact rule would keep it, so it is not a
  // candidate; empty orthants have position kNoPoint, which no point has, and distance +inf).
  __attribute__((target("avx2"), always_inline)) inline unsigned Candidates(
      __m256d dist, const __m256d* plus, __m256i positions) const {
    // The permute's index per 64-bit lane: 32-bit elements 2(o & 3) and 2(o & 3) + 1.
    const __m256i index = _mm256_or_si256(
        _mm256_set1_epi64x(std::int64_t{1} << 32),
        _mm256_or_si256(
            _mm256_and_si256(_mm256_castpd_si256(plus[0]), _mm256_set1_epi64x(0x0000000200000002)),
            _mm256_and_si256(_mm256_castpd_si256(plus[1]),
                             _mm256_set1_epi64x(0x0000000400000004))));
    __m256d limit[kRegs];
    __m256i at[kRegs];
    for (int r = 0; r < kRegs; ++r) {
      limit[r] = _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(d2[r]), index));
      at[r] = _mm256_permutevar8x32_epi32(pos[r], index);
    }
    __m256d l = _mm256_blendv_pd(limit[0], limit[1], plus[2]);
    __m256i a = _mm256_castpd_si256(
        _mm256_blendv_pd(_mm256_castsi256_pd(at[0]), _mm256_castsi256_pd(at[1]), plus[2]));
    if constexpr (D == 4) {
      const __m256d l23 = _mm256_blendv_pd(limit[2], limit[3], plus[2]);
      const __m256d a23 =
          _mm256_blendv_pd(_mm256_castsi256_pd(at[2]), _mm256_castsi256_pd(at[3]), plus[2]);
      l = _mm256_blendv_pd(l, l23, plus[3]);
      a = _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(a), a23, plus[3]));
    }
    const __m256d below = _mm256_cmp_pd(dist, l, _CMP_LT_OQ);
    const __m256d equal = _mm256_cmp_pd(dist, l, _CMP_EQ_OQ);
    const __m256d same = _mm256_castsi256_pd(_mm256_cmpeq_epi64(positions, a));
    return static_cast<unsigned>(
        _mm256_movemask_pd(_mm256_or_pd(below, _mm256_andnot_pd(same, equal))));
  }

  // After OrthantBest::Offer: when the point won orthant o, the registers take its distance and
  // position (no reload from memory: that would stall on store forwarding).
  __attribute__((target("avx2"), always_inline)) inline void Update(bool better, unsigned o,
                                                                    double dist, std::uint32_t at) {
    // Orthant 16 is no orthant: a point that did not win changes nothing.
    const auto target = static_cast<std::int64_t>(better ? o : 16u);
    const __m256i which = _mm256_set1_epi64x(target);
    const __m256d d = _mm256_set1_pd(dist);
    const __m256d p = _mm256_castsi256_pd(_mm256_set1_epi64x(at));
    for (int r = 0; r < kRegs; ++r) {
      const __m256d m = _mm256_castsi256_pd(
          _mm256_cmpeq_epi64(which, _mm256_set_epi64x(4 * r + 3, 4 * r + 2, 4 * r + 1, 4 * r)));
      d2[r] = _mm256_blendv_pd(d2[r], d, m);
      pos[r] = _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(pos[r]), p, m));
    }
  }

  // Squared distances ((0 + dx²) + dy²) + dz² (+ dw², each square rounded) and sides (plus[j]:
  // x_j >= q_j) of the four points whose coordinates are v[j], lane by lane.
  __attribute__((target("avx2"), always_inline)) static inline __m256d Measure(const __m256d* v,
                                                                               const __m256d* q,
                                                                               __m256d* plus) {
    __m256d d2 = _mm256_setzero_pd();
#pragma GCC unroll 4
    for (int j = 0; j < D; ++j) {
      const __m256d diff = _mm256_sub_pd(v[j], q[j]);
      __m256d sq = _mm256_mul_pd(diff, diff);
      asm("" : "+x"(sq));  // no fused multiply-add: round the square first
      d2 = j == 0 ? sq : _mm256_add_pd(d2, sq);
      plus[j] = _mm256_cmp_pd(v[j], q[j], _CMP_GE_OQ);
    }
    return d2;
  }

  // The exact rule (OrthantBest::Offer) for each lane of `candidates`, lane k being the point at
  // tree position at[k]; the registers follow. True when some orthant improved.
  __attribute__((target("avx2"), always_inline)) inline bool Offer(
      unsigned candidates, __m256d dist2, const __m256d* plus, const std::uint32_t* at,
      const std::uint32_t* rank, KdTree::OrthantBest& best) {
    alignas(32) double dist[4];
    alignas(32) std::int64_t orthant[4];
    _mm256_store_pd(dist, dist2);
    _mm256_store_si256(reinterpret_cast<__m256i*>(orthant), Code(plus));
    bool improved = false;
    for (; candidates != 0; candidates &= candidates - 1) {
      const int lane = std::countr_zero(candidates);
      const std::uint32_t point = at[lane];
      const auto o = static_cast<unsigned>(orthant[lane]);
      const bool better = best.Offer(o, dist[lane], rank[point], point);
      Update(better, o, dist[lane], point);
      improved |= better;
    }
    return improved;
  }

  // Lane masks of the orthants in `need` (bit o for orthant o).
  __attribute__((target("avx2"), always_inline)) static inline void NeedMask(unsigned need,
                                                                             __m256d* keep) {
    for (int r = 0; r < kRegs; ++r) {
      const __m256i bits = _mm256_set1_epi64x(need >> (4 * r));
      const __m256i lane = _mm256_set_epi64x(8, 4, 2, 1);
      keep[r] = _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(bits, lane), lane));
    }
  }

  // The largest best among the orthants of `keep` (the others count as 0: bests are never
  // negative, so this is the largest needed one whenever one is needed).
  __attribute__((target("avx2"), always_inline)) inline double Worst(const __m256d* keep) const {
    __m256d m = _mm256_and_pd(d2[0], keep[0]);
    for (int r = 1; r < kRegs; ++r) m = _mm256_max_pd(m, _mm256_and_pd(d2[r], keep[r]));
    const __m128d h = _mm_max_pd(_mm256_castpd256_pd128(m), _mm256_extractf128_pd(m, 1));
    return _mm_cvtsd_f64(_mm_max_sd(h, _mm_unpackhi_pd(h, h)));
  }
};
#endif

#ifdef BRDF_KD_X86
// The per-orthant bests of a search held in AVX-512 registers, for the AVX-512 kernels: the
// squared distances of orthants 0–7 in d2_lo and 8–15 in d2_hi (4D), their tree positions widened
// to 64 bits in pos_lo and pos_hi; an orthant's best reaches a lane by a permute. The memory copy
// (OrthantBest) stays the exact record; the registers follow every update (reloading them from
// its scalar stores would stall on store forwarding).
template <int D>
struct Avx512Bests {
  __m512d d2_lo, d2_hi;
  __m512i pos_lo, pos_hi;

  __attribute__((target("avx512f"), always_inline)) inline void Load(
      const KdTree::OrthantBest& best) {
    d2_lo = _mm512_loadu_pd(best.d2.data());
    d2_hi = _mm512_loadu_pd(best.d2.data() + 8);
    pos_lo = _mm512_maskz_cvtepu32_epi64(
        0xFF, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(best.pos.data())));
    pos_hi = _mm512_maskz_cvtepu32_epi64(
        0xFF, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(best.pos.data() + 8)));
  }

  // The lanes (bit k for lane k) whose point (squared distance d2, orthant code, tree position)
  // is nearer than its orthant's best, or as near but not that very point: the seeds are met
  // again in their leaves (and lists repeat their last entry), and each such meeting would cost
  // an unpredictable branch and a pass through the exact rule for nothing (Offer keeps the best:
  // same distance, same rank). Empty orthants keep position kNoPoint, which no point has.
  __attribute__((target("avx512f"), always_inline)) inline unsigned Candidates(
      __m512d d2, __m512i code, __m512i positions) const {
    const __m512d limit =
        D == 3 ? _mm512_permutexvar_pd(code, d2_lo) : _mm512_permutex2var_pd(d2_lo, code, d2_hi);
    const __m512i at = D == 3 ? _mm512_permutexvar_epi64(code, pos_lo)
                              : _mm512_permutex2var_epi64(pos_lo, code, pos_hi);
    return _mm512_cmp_pd_mask(d2, limit, _CMP_LT_OQ) |
           _mm512_mask_cmpneq_epi64_mask(_mm512_cmp_pd_mask(d2, limit, _CMP_EQ_OQ), positions, at);
  }

  // After OrthantBest::Offer: when the point at tree position `at` won orthant o, the registers
  // take its distance and position.
  __attribute__((target("avx512f"), always_inline)) inline void Follow(bool better, unsigned o,
                                                                       double dist,
                                                                       std::uint32_t at) {
    const unsigned mask = static_cast<unsigned>(better) << o;
    const __m512d d = _mm512_set1_pd(dist);
    const __m512i p = _mm512_set1_epi64(at);
    d2_lo = _mm512_mask_mov_pd(d2_lo, static_cast<__mmask8>(mask), d);
    pos_lo = _mm512_mask_mov_epi64(pos_lo, static_cast<__mmask8>(mask), p);
    if (D == 4) {
      d2_hi = _mm512_mask_mov_pd(d2_hi, static_cast<__mmask8>(mask >> 8), d);
      pos_hi = _mm512_mask_mov_epi64(pos_hi, static_cast<__mmask8>(mask >> 8), p);
    }
  }
};
#endif

// The leaf scans. Each computes, for every point of the leaf, its orthant (bit j set when
// x_j >= q_j) and its squared distance ((0 + dx²) + dy²) + dz² (+ dw²), exactly as OrthantOf and
// SquaredDistance do, and offers it to its orthant.
template <int D>
struct LeafKernels {
  using Best = KdTree::OrthantBest;

  // Portable: no data-dependent branch per point (the update is a masked select).
  static bool Scalar(const KdTree::Entries& tree, std::uint32_t begin, std::uint32_t end,
                     Best& best) {
    const double* x[D];
    for (int j = 0; j < D; ++j) x[j] = tree.axis[j];
    double q[D];
    for (int j = 0; j < D; ++j) q[j] = best.q[static_cast<std::size_t>(j)];
    bool improved = false;
    for (std::uint32_t pos = begin; pos < end; ++pos) {
      unsigned o = 0;
      double d2 = 0.0;
#pragma GCC unroll 4
      for (int j = 0; j < D; ++j) {
        const double v = x[j][pos];
        o |= static_cast<unsigned>(v >= q[j]) << j;
        d2 += RoundedSquare(v - q[j]);
      }
      improved |= best.Offer(o, d2, tree.rank[pos], pos);
    }
    return improved;
  }

  // Portable: a grid list (see ListAvx512), one point at a time.
  static void ListScalar(const KdTree& tree, const std::uint32_t* entry, const double* block_gap,
                         std::uint32_t blocks, unsigned need, Best& best) {
    double q[D];
    for (int j = 0; j < D; ++j) q[j] = best.q[static_cast<std::size_t>(j)];
    double worst = kInf;
    for (std::uint32_t b = 0; b < blocks; ++b) {
      if (block_gap[b] > worst) break;
      bool improved = false;
      for (std::uint32_t k = 0; k < 8; ++k) {
        const std::uint32_t pos = entry[std::size_t{b} * 8 + k];
        unsigned o = 0;
        double d2 = 0.0;
#pragma GCC unroll 4
        for (int j = 0; j < D; ++j) {
          const double v = tree.axis_[static_cast<std::size_t>(j)][pos];
          o |= static_cast<unsigned>(v >= q[j]) << j;
          d2 += RoundedSquare(v - q[j]);
        }
        improved |= best.Offer(o, d2, tree.rank_[pos], pos);
      }
      if (!improved) continue;
      worst = -kInf;  // orthants outside `need` are empty for every query of the cell
      for (int o = 0; o < (1 << D); ++o) {
        if ((need >> o) & 1u) worst = Max(worst, best.d2[static_cast<std::size_t>(o)]);
      }
    }
  }

#ifdef BRDF_KD_X86
  // 4 points at a time, the bests in registers (Avx2Bests): only a point below its orthant's
  // best, or at it but not that very point, goes through the exact rule.
  __attribute__((target("avx2"))) static bool Avx2(const KdTree::Entries& tree, std::uint32_t begin,
                                                   std::uint32_t end, Best& best) {
    __m256d q[D];
    for (int j = 0; j < D; ++j) q[j] = _mm256_set1_pd(best.q[static_cast<std::size_t>(j)]);
    const double* axis[D];
    for (int j = 0; j < D; ++j) axis[j] = tree.axis[j];
    const std::uint32_t* rank = tree.rank;
    Avx2Bests<D> bests;
    bests.Load(best);
    const __m256i lane_index = _mm256_set_epi64x(3, 2, 1, 0);
    bool improved = false;
    for (std::uint32_t pos = begin; pos < end; pos += 4) {
      __m256d v[D];
#pragma GCC unroll 4
      for (int j = 0; j < D; ++j) v[j] = _mm256_loadu_pd(axis[j] + pos);
      __m256d plus[D];
      const __m256d d2 = Avx2Bests<D>::Measure(v, q, plus);
      const __m256i positions = _mm256_add_epi64(_mm256_set1_epi64x(pos), lane_index);
      unsigned candidates = bests.Candidates(d2, plus, positions);
      if (end - pos < 4) candidates &= (1u << (end - pos)) - 1u;
      if (candidates == 0) continue;
      const std::uint32_t at[4] = {pos, pos + 1, pos + 2, pos + 3};
      improved |= bests.Offer(candidates, d2, plus, at, rank, best);
    }
    return improved;
  }

  // 4 points at a time; the bests of their orthants are gathered, and only a point at or below
  // its orthant's best goes through the exact rule.
  __attribute__((target("avx2"))) static bool Avx2Gather(const KdTree::Entries& tree,
                                                         std::uint32_t begin, std::uint32_t end,
                                                         Best& best) {
    __m256d q[D];
    for (int j = 0; j < D; ++j) q[j] = _mm256_set1_pd(best.q[static_cast<std::size_t>(j)]);
    bool improved = false;
    for (std::uint32_t pos = begin; pos < end; pos += 4) {
      __m256d v[D];
#pragma GCC unroll 4
      for (int j = 0; j < D; ++j) v[j] = _mm256_loadu_pd(tree.axis[j] + pos);
      __m256d plus[D];
      const __m256d d2 = Avx2Bests<D>::Measure(v, q, plus);
      const __m256i code = Avx2Bests<D>::Code(plus);
      const __m256d limit = _mm256_i64gather_pd(best.d2.data(), code, 8);
      unsigned candidates =
          static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(d2, limit, _CMP_LE_OQ)));
      if (end - pos < 4) candidates &= (1u << (end - pos)) - 1u;
      if (candidates == 0) continue;
      alignas(32) double dist[4];
      alignas(32) std::int64_t orthant[4];
      _mm256_store_pd(dist, d2);
      _mm256_store_si256(reinterpret_cast<__m256i*>(orthant), code);
      for (; candidates != 0; candidates &= candidates - 1) {
        const int lane = std::countr_zero(candidates);
        const std::uint32_t at = pos + static_cast<std::uint32_t>(lane);
        improved |=
            best.Offer(static_cast<std::size_t>(orthant[lane]), dist[lane], tree.rank[at], at);
      }
    }
    return improved;
  }

  // A grid list (see ListAvx512), 4 points at a time: their coordinates gathered from the tree's
  // per-axis arrays, the bests in registers (Avx2Bests).
  __attribute__((target("avx2"))) static void ListAvx2(const KdTree& tree,
                                                       const std::uint32_t* entry,
                                                       const double* block_gap,
                                                       std::uint32_t blocks, unsigned need,
                                                       Best& best) {
    __m256d q[D];
    for (int j = 0; j < D; ++j) q[j] = _mm256_set1_pd(best.q[static_cast<std::size_t>(j)]);
    // In locals: the stores into `best` below could alias the tree's members for the compiler,
    // which would reload them for every block.
    const double* axis[D];
    for (int j = 0; j < D; ++j) axis[j] = tree.axis_[static_cast<std::size_t>(j)].data();
    const std::uint32_t* rank = tree.rank_.data();
    Avx2Bests<D> bests;
    bests.Load(best);
    __m256d keep[Avx2Bests<D>::kRegs];
    Avx2Bests<D>::NeedMask(need, keep);
    double worst = kInf;
    for (std::uint32_t b = 0; b < blocks; ++b) {
      if (block_gap[b] > worst) break;
      bool improved = false;
#pragma GCC unroll 2
      for (std::uint32_t half = 0; half < 2; ++half) {
        const std::uint32_t* at = entry + std::size_t{b} * 8 + half * 4;
        const __m128i index = _mm_loadu_si128(reinterpret_cast<const __m128i*>(at));
        __m256d v[D];
#pragma GCC unroll 4
        for (int j = 0; j < D; ++j) v[j] = _mm256_i32gather_pd(axis[j], index, 8);
        __m256d plus[D];
        const __m256d d2 = Avx2Bests<D>::Measure(v, q, plus);
        // As in Avx2: a point equal to its orthant's best is a candidate only when it is not that
        // point itself (lists repeat their last entry as padding).
        const unsigned candidates = bests.Candidates(d2, plus, _mm256_cvtepu32_epi64(index));
        if (candidates == 0) continue;
        improved |= bests.Offer(candidates, d2, plus, at, rank, best);
      }
      if (!improved) continue;
      worst = bests.Worst(keep);
    }
  }

  // 8 points at a time; the orthants' bests sit in one (3D) or two (4D) registers and are
  // permuted into place.
  __attribute__((target("avx512f"))) static bool Avx512(const KdTree::Entries& tree,
                                                        std::uint32_t begin, std::uint32_t end,
                                                        Best& best) {
    __m512d q[D];
    for (int j = 0; j < D; ++j) q[j] = _mm512_set1_pd(best.q[static_cast<std::size_t>(j)]);
    bool improved = false;
    Avx512Bests<D> bests;
    bests.Load(best);
    const __m512i lane_index = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
    for (std::uint32_t pos = begin; pos < end; pos += 8) {
      __m512d d2 = _mm512_setzero_pd();
      __m512i code = _mm512_setzero_si512();
#pragma GCC unroll 4
      for (int j = 0; j < D; ++j) {
        const __m512d v = _mm512_loadu_pd(tree.axis[j] + pos);
        const __m512d diff = _mm512_sub_pd(v, q[j]);
        __m512d sq = _mm512_mul_pd(diff, diff);
        asm("" : "+v"(sq));  // no fused multiply-add: round the square first
        d2 = j == 0 ? sq : _mm512_add_pd(d2, sq);
        const __mmask8 plus = _mm512_cmp_pd_mask(v, q[j], _CMP_GE_OQ);
        code = _mm512_mask_or_epi64(code, plus, code, _mm512_set1_epi64(1 << j));
      }
      const __m512i positions = _mm512_add_epi64(_mm512_set1_epi64(pos), lane_index);
      unsigned candidates = bests.Candidates(d2, code, positions);
      if (end - pos < 8) candidates &= (1u << (end - pos)) - 1u;
      if (candidates == 0) continue;
      alignas(64) double dist[8];
      alignas(64) std::int64_t orthant[8];
      _mm512_store_pd(dist, d2);
      _mm512_store_si512(orthant, code);
      // The exact rule point by point; the vector copies of the bests follow in registers
      // (reloading them from the scalar stores would stall on store forwarding).
      for (; candidates != 0; candidates &= candidates - 1) {
        const int lane = std::countr_zero(candidates);
        const std::uint32_t at = pos + static_cast<std::uint32_t>(lane);
        const auto o = static_cast<unsigned>(orthant[lane]);
        const bool better = best.Offer(o, dist[lane], tree.rank[at], at);
        improved |= better;
        bests.Follow(better, o, dist[lane], at);
      }
    }
    return improved;
  }
  // A grid list (search/orthant_grid.h): tree positions, 8 per block, nearest blocks first. Stops
  // at the first block whose bound exceeds the best of every orthant in `need`. 8 points at a time,
  // their coordinates gathered from the tree's per-axis arrays (small: they stay in cache).
  __attribute__((target("avx512f"))) static void ListAvx512(const KdTree& tree,
                                                            const std::uint32_t* entry,
                                                            const double* block_gap,
                                                            std::uint32_t blocks, unsigned need,
                                                            Best& best) {
    __m512d q[D];
    for (int j = 0; j < D; ++j) q[j] = _mm512_set1_pd(best.q[static_cast<std::size_t>(j)]);
    Avx512Bests<D> bests;
    bests.Load(best);
    const auto need_lo = static_cast<__mmask8>(need & 0xFFu);
    const auto need_hi = static_cast<__mmask8>(need >> 8);
    // In locals: the stores into `best` below could alias the tree's members for the compiler,
    // which would reload them for every block.
    const double* axis[D];
    for (int j = 0; j < D; ++j) axis[j] = tree.axis_[static_cast<std::size_t>(j)].data();
    const std::uint32_t* rank = tree.rank_.data();
    double worst = kInf;
    for (std::uint32_t b = 0; b < blocks; ++b) {
      if (block_gap[b] > worst) break;
      const std::uint32_t* at = entry + std::size_t{b} * 8;
      const __m256i index = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(at));
      __m512d d2 = _mm512_setzero_pd();
      __m512i code = _mm512_setzero_si512();
#pragma GCC unroll 4
      for (int j = 0; j < D; ++j) {
        const __m512d v = _mm512_i32gather_pd(index, axis[j], 8);
        const __m512d diff = _mm512_sub_pd(v, q[j]);
        __m512d sq = _mm512_mul_pd(diff, diff);
        asm("" : "+v"(sq));  // no fused multiply-add: round the square first
        d2 = j == 0 ? sq : _mm512_add_pd(d2, sq);
        const __mmask8 plus = _mm512_cmp_pd_mask(v, q[j], _CMP_GE_OQ);
        code = _mm512_mask_or_epi64(code, plus, code, _mm512_set1_epi64(1 << j));
      }
      // Lists repeat their last entry as padding: it meets itself as its orthant's best.
      unsigned candidates = bests.Candidates(d2, code, _mm512_cvtepu32_epi64(index));
      if (candidates == 0) continue;
      alignas(64) double dist[8];
      alignas(64) std::int64_t orthant[8];
      _mm512_store_pd(dist, d2);
      _mm512_store_si512(orthant, code);
      // The exact rule point by point; the vector copies of the bests follow in registers
      // (reloading them from the scalar stores would stall on store forwarding).
      for (; candidates != 0; candidates &= candidates - 1) {
        const int lane = std::countr_zero(candidates);
        const std::uint32_t pos = at[lane];
        const auto o = static_cast<unsigned>(orthant[lane]);
        bests.Follow(best.Offer(o, dist[lane], rank[pos], pos), o, dist[lane], pos);
      }
      // Orthants outside `need` count as -inf (empty for every query of the cell).
      worst = _mm512_mask_reduce_max_pd(need_lo, bests.d2_lo);
      if (D == 4) worst = Max(worst, _mm512_mask_reduce_max_pd(need_hi, bests.d2_hi));
    }
  }
#endif
};

bool KdTree::Supported(Kernel kernel) {
  switch (kernel) {
    case Kernel::kBest:
    case Kernel::kScalar:
      return true;
#ifdef BRDF_KD_X86
    case Kernel::kAvx2:
      return __builtin_cpu_supports("avx2");
    case Kernel::kAvx512:
      return __builtin_cpu_supports("avx512f");
#else
    case Kernel::kAvx2:
    case Kernel::kAvx512:
      return false;
#endif
  }
  return false;
}

const char* KdTree::KernelName(Kernel kernel) {
  switch (kernel) {
    case Kernel::kBest:
      return "best";
    case Kernel::kScalar:
      return "scalar";
    case Kernel::kAvx2:
      return "avx2";
    case Kernel::kAvx512:
      return "avx512";
  }
  return "unknown";
}

KdTree::KdTree(const PointCloud& cloud, Kernel kernel, Search search)
    : cloud_(&cloud), dims_(cloud.dims) {
  if (kernel == Kernel::kBest) {
    kernel = Supported(Kernel::kAvx512) ? Kernel::kAvx512
             : Supported(Kernel::kAvx2) ? Kernel::kAvx2
                                        : Kernel::kScalar;
  }
  if (!Supported(kernel)) kernel = Kernel::kScalar;
  kernel_ = kernel;
  // Wider kernels make points cheaper relative to deciding whether to visit a node (which is
  // hard to predict), so their leaves are larger (measured with bench/).
  leaf_size_ = kernel == Kernel::kAvx512 ? 96 : kernel == Kernel::kAvx2 ? 64 : 32;

  const bool three = dims_ == 3;
  switch (kernel) {
#ifdef BRDF_KD_X86
    case Kernel::kAvx512:
      scan_ = three ? &LeafKernels<3>::Avx512 : &LeafKernels<4>::Avx512;
      break;
    case Kernel::kAvx2:
      // 4D keeps the gather: its 16 bests would take 8 registers and 14 permutes and blends per
      // 4 points (spilled; measured no faster than one vgatherqpd).
      scan_ = three ? &LeafKernels<3>::Avx2 : &LeafKernels<4>::Avx2Gather;
      break;
#endif
    default:
      scan_ = three ? &LeafKernels<3>::Scalar : &LeafKernels<4>::Scalar;
  }
  list_scan_ = three ? &LeafKernels<3>::ListScalar : &LeafKernels<4>::ListScalar;
#ifdef BRDF_KD_X86
  if (kernel == Kernel::kAvx512) {
    list_scan_ = three ? &LeafKernels<3>::ListAvx512 : &LeafKernels<4>::ListAvx512;
  } else if (kernel == Kernel::kAvx2) {
    list_scan_ = three ? &LeafKernels<3>::ListAvx2 : &LeafKernels<4>::ListAvx2;
  }
#endif

  const auto n = static_cast<std::uint32_t>(cloud.size());
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * (n / (leaf_size_ / 2)) + 2);
  Build(order, 0, n);
  const auto d = static_cast<std::size_t>(dims_);
  for (std::size_t j = 0; j < d; ++j) {
    auto& a = axis_[j];
    a.resize(n + kPadding);
    for (std::size_t pos = 0; pos < n; ++pos) a[pos] = cloud.scaled[order[pos] * d + j];
    std::fill(a.begin() + n, a.end(), a[n - 1]);
  }
  rank_ = std::move(order);
  rank_.resize(n + kPadding, kNoPoint);
  BuildSeeds();
  if (search == Search::kGridThenTree) {
    std::vector<std::uint32_t> position_of(n);
    for (std::uint32_t pos = 0; pos < n; ++pos) position_of[rank_[pos]] = pos;
    grid_ = OrthantGrid(cloud, position_of, [this](const double* p, OrthantWinners& winners) {
      NearestPerOrthant(p, winners);  // the grid is still empty: the tree answers
    });
  }
}

std::uint32_t KdTree::Build(std::vector<std::uint32_t>& order, std::uint32_t begin,
                            std::uint32_t end) {
  const PointCloud& cloud = *cloud_;
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node{};
  node.begin = begin;
  node.end = end;
  node.lo.fill(kInf);
  node.hi.fill(-kInf);
  for (std::uint32_t k = begin; k < end; ++k) {
    const auto x = cloud.scaled_point(order[k]);
    for (int j = 0; j < dims_; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      node.lo[uj] = std::min(node.lo[uj], x[uj]);
      node.hi[uj] = std::max(node.hi[uj], x[uj]);
    }
  }
  int axis = 0;
  for (int j = 1; j < dims_; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const auto ua = static_cast<std::size_t>(axis);
    if (node.hi[uj] - node.lo[uj] > node.hi[ua] - node.lo[ua]) axis = j;
  }
  const auto ua = static_cast<std::size_t>(axis);
  // A leaf when small, or when every point is the same (duplicates cannot be split apart).
  if (end - begin <= leaf_size_ || !(node.hi[ua] > node.lo[ua])) {
    nodes_[index] = node;
    return index;
  }
  const std::uint32_t mid = begin + (end - begin) / 2;
  const auto d = static_cast<std::size_t>(dims_);
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) {
                     const double ca = cloud.scaled[a * d + ua];
                     const double cb = cloud.scaled[b * d + ua];
                     return ca < cb || (ca == cb && a < b);
                   });
  node.axis = static_cast<std::uint32_t>(axis);
  node.split = cloud.scaled[order[mid] * d + ua];
  nodes_[index] = node;
  Build(order, begin, mid);
  const std::uint32_t right = Build(order, mid, end);
  nodes_[index].right = right;
  return index;
}

template <int D>
void KdTree::VisitOrthants(std::uint32_t node_index, OrthantBest& best) const {
  const Node& node = nodes_[node_index];
  // The box's side pattern and its distance from the query. On an axis where the box lies
  // entirely on one side of the query it reaches only that side, so the box's distance is also
  // the bound for every orthant it reaches.
  unsigned lt = 0, ge = 0;
  double bound = 0.0;
#pragma GCC unroll 4
  for (int j = 0; j < D; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double lo = node.lo[uj], hi = node.hi[uj], q = best.q[uj];
    lt |= static_cast<unsigned>(lo < q) << j;
    ge |= static_cast<unsigned>(hi >= q) << j;
    const double gap = Max(Max(lo - q, q - hi), 0.0);
    bound += gap * gap;
  }
  if ((best.Open<D>(bound * kBoundShrink) & kReach<D>[lt | (ge << D)]) == 0) return;

  if (node.right == 0) {
    const Entries entries{{axis_[0].data(), axis_[1].data(), axis_[2].data(), axis_[3].data()},
                          rank_.data()};
    scan_(entries, node.begin, node.end, best);
    return;
  }
  if (best.q[node.axis] < node.split) {
    VisitOrthants<D>(node_index + 1, best);
    VisitOrthants<D>(node.right, best);
  } else {
    VisitOrthants<D>(node.right, best);
    VisitOrthants<D>(node_index + 1, best);
  }
}

#ifdef BRDF_KD_X86
// VisitOrthants with the box's distance and sides computed for all axes at once (AVX2): the
// scalar version's three chains of subtractions, maxima and squares per node were the walk's
// critical path. The sum of the squared gaps is formed in another order ((g0 + g2) + (g1 + g3));
// kBoundShrink covers the difference, so the bound still never exceeds a point's distance.
template <int D>
__attribute__((target("avx2"))) void KdTree::VisitOrthantsAvx2(std::uint32_t root,
                                                               OrthantBest& best) const {
  const __m256d q = _mm256_loadu_pd(best.q.data());
  constexpr unsigned kAxes = (1u << D) - 1u;
  // Depth first, nearer child first, as VisitOrthants recurses: the farther child waits on a
  // stack and is tested when it is taken, against the bests as they are then. (Iterative: the
  // calls' prologues and epilogues were a good part of the recursive walk.)
  // Every split halves its node's points, so a tree over fewer than 2^32 points is at most 32
  // levels deep, and the stack holds at most one node per level.
  std::uint32_t stack[64];
  int top = 0;
  std::uint32_t node_index = root;
  for (;;) {
    const Node& node = nodes_[node_index];
    const __m256d lo = _mm256_loadu_pd(node.lo.data());
    const __m256d hi = _mm256_loadu_pd(node.hi.data());
    __m256d gap = _mm256_max_pd(_mm256_max_pd(_mm256_sub_pd(lo, q), _mm256_sub_pd(q, hi)),
                                _mm256_setzero_pd());
    // 3D: the fourth axis is unused (its box is empty: +inf … −inf).
    if constexpr (D == 3) gap = _mm256_blend_pd(gap, _mm256_setzero_pd(), 0x8);
    const __m256d square = _mm256_mul_pd(gap, gap);
    const __m128d half =
        _mm_add_pd(_mm256_castpd256_pd128(square), _mm256_extractf128_pd(square, 1));
    const double bound = _mm_cvtsd_f64(_mm_add_sd(half, _mm_unpackhi_pd(half, half)));
    const unsigned lt =
        static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(lo, q, _CMP_LT_OQ))) & kAxes;
    const unsigned ge =
        static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(hi, q, _CMP_GE_OQ))) & kAxes;
    // The orthants whose best is at least the bound (OrthantBest::Open).
    const __m256d b = _mm256_set1_pd(bound * kBoundShrink);
    unsigned open = 0;
#pragma GCC unroll 4
    for (int o = 0; o < (1 << D); o += 4) {
      open |= static_cast<unsigned>(_mm256_movemask_pd(
                  _mm256_cmp_pd(b, _mm256_loadu_pd(best.d2.data() + o), _CMP_LE_OQ)))
              << o;
    }
    if ((open & kReach<D>[lt | (ge << D)]) != 0) {
      if (node.right != 0) {
        const bool left_first = best.q[node.axis] < node.split;
        stack[top++] = left_first ? node.right : node_index + 1;
        node_index = left_first ? node_index + 1 : node.right;
        continue;
      }
      const Entries entries{{axis_[0].data(), axis_[1].data(), axis_[2].data(), axis_[3].data()},
                            rank_.data()};
      scan_(entries, node.begin, node.end, best);
    }
    if (top == 0) return;
    node_index = stack[--top];
  }
}
#endif

template <int D>
void KdTree::VisitNearest(std::uint32_t node_index, const double* p, NearestBest& best) const {
  const Node& node = nodes_[node_index];
  double bound = 0.0;
#pragma GCC unroll 4
  for (int j = 0; j < D; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double gap = Max(Max(node.lo[uj] - p[j], p[j] - node.hi[uj]), 0.0);
    bound += gap * gap;
  }
  if (!(bound * kBoundShrink <= best.d2)) return;

  if (node.right == 0) {
    for (std::uint32_t pos = node.begin; pos < node.end; ++pos) {
      double d2 = 0.0;
#pragma GCC unroll 4
      for (int j = 0; j < D; ++j)
        d2 += RoundedSquare(axis_[static_cast<std::size_t>(j)][pos] - p[j]);
      const std::uint32_t r = rank_[pos];
      if (d2 < best.d2 || (d2 == best.d2 && r < best.rank)) {
        best.d2 = d2;
        best.rank = r;
      }
    }
    return;
  }
  if (p[node.axis] < node.split) {
    VisitNearest<D>(node_index + 1, p, best);
    VisitNearest<D>(node.right, p, best);
  } else {
    VisitNearest<D>(node.right, p, best);
    VisitNearest<D>(node_index + 1, p, best);
  }
}

void KdTree::BuildSeeds() {
  // About two points per cell; a few thousand cells at most (3D: up to 32³, 4D: up to 12⁴).
  const double n = static_cast<double>(rank_.size() - kPadding);
  const int cap = dims_ == 3 ? 32 : 12;
  seed_cells_ = std::clamp(static_cast<int>(std::lround(std::pow(n / 2.0, 1.0 / dims_))), 2, cap);
  const auto d = static_cast<std::size_t>(dims_);
  const Node& root = nodes_[0];
  std::size_t cells = 1;
  for (std::size_t j = 0; j < d; ++j) {
    seed_lo_[j] = root.lo[j];
    const double extent = root.hi[j] - root.lo[j];
    seed_inv_[j] = extent > 0 ? seed_cells_ / extent : 0.0;
    cells *= static_cast<std::size_t>(seed_cells_);
  }
  const std::size_t orthants = std::size_t{1} << dims_;
  seeds_.assign(cells * orthants, kNoPoint);
  std::array<double, 4> centre{};
  for (std::size_t cell = 0; cell < cells; ++cell) {
    std::size_t rest = cell;
    for (std::size_t j = d; j-- > 0;) {
      const auto k = static_cast<double>(rest % static_cast<std::size_t>(seed_cells_));
      rest /= static_cast<std::size_t>(seed_cells_);
      centre[j] = seed_inv_[j] > 0 ? seed_lo_[j] + (k + 0.5) / seed_inv_[j] : seed_lo_[j];
    }
    OrthantBest best;
    best.q = centre;
    best.Clear();
    if (dims_ == 3) {
      VisitOrthants<3>(0, best);
    } else {
      VisitOrthants<4>(0, best);
    }
    for (std::size_t o = 0; o < orthants; ++o) {
      seeds_[cell * orthants + o] = best.rank[o] == kNoPoint ? kNoPoint : best.pos[o];
    }
  }
}

std::size_t KdTree::HeapBytes() const {
  std::size_t bytes = nodes_.capacity() * sizeof(Node) +
                      (rank_.capacity() + seeds_.capacity()) * sizeof(std::uint32_t);
  for (const std::vector<double>& axis : axis_) bytes += axis.capacity() * sizeof(double);
  return bytes + grid_.bytes();
}

std::uint32_t KdTree::SeedCell(const double* p) const {
  std::size_t cell = 0;
  for (std::size_t j = 0; j < static_cast<std::size_t>(dims_); ++j) {
    const double f = (p[j] - seed_lo_[j]) * seed_inv_[j];
    const int k = f > 0.0 ? static_cast<int>(std::min(f, static_cast<double>(seed_cells_ - 1))) : 0;
    cell = cell * static_cast<std::size_t>(seed_cells_) + static_cast<std::size_t>(k);
  }
  return static_cast<std::uint32_t>(cell);
}

void KdTree::Seed(OrthantBest& best) const {
  if (seeds_.empty()) return;
  const std::size_t cell = SeedCell(best.q.data());
  const std::size_t orthants = std::size_t{1} << dims_;
  const std::uint32_t* seed = seeds_.data() + cell * orthants;
  const auto d = static_cast<std::size_t>(dims_);
  for (std::size_t s = 0; s < orthants; ++s) {
    const std::uint32_t pos = seed[s];
    if (pos == kNoPoint) continue;
    unsigned o = 0;
    double d2 = 0.0;
    for (std::size_t j = 0; j < d; ++j) {
      const double v = axis_[j][pos];
      o |= static_cast<unsigned>(v >= best.q[j]) << j;
      d2 += RoundedSquare(v - best.q[j]);
    }
    best.Offer(o, d2, rank_[pos], pos);
  }
}

template <int D>
void KdTree::FillWinners(const std::uint32_t* pos, OrthantWinners& winners) const {
  // The coordinates from the per-axis arrays, whose lines the search just read.
  for (std::size_t o = 0; o < (std::size_t{1} << D); ++o) {
    winners.scaled[o] = nullptr;
    if (pos[o] == kNoPoint) {
      winners.rank[o] = kNoPoint;
      continue;
    }
    winners.rank[o] = rank_[pos[o]];
    for (std::size_t j = 0; j < D; ++j) winners.coords[o][j] = axis_[j][pos[o]];
    winners.scaled[o] = winners.coords[o].data();
  }
}

template <int D>
void KdTree::SearchOrthants(OrthantBest& best, OrthantWinners& winners) const {
  best.Clear();
  std::uint32_t begin = 0, count = 0, need = 0;
  if (grid_.Find<D>(best.q.data(), begin, count, need)) {
    // The cell's list holds every possible winner, nearest to the cell first: one short scan, no
    // tree.
    list_scan_(*this, grid_.entry() + begin, grid_.block_gap() + begin / 8, count / 8, need, best);
  } else {
    Seed(best);
#ifdef BRDF_KD_X86
    if (kernel_ != Kernel::kScalar) {  // the AVX2 and AVX-512 kernels' CPUs have AVX2
      VisitOrthantsAvx2<D>(0, best);
    } else {
      VisitOrthants<D>(0, best);
    }
#else
    VisitOrthants<D>(0, best);
#endif
  }
  FillWinners<D>(best.pos.data(), winners);
}

void KdTree::NearestPerOrthant(const double* p, OrthantWinners& winners) const {
  OrthantBest best;
  // Coordinate by coordinate: std::copy of three doubles became a call to memmove.
  best.q = {p[0], p[1], p[2], dims_ == 4 ? p[3] : 0.0};
  if (dims_ == 3) {
    SearchOrthants<3>(best, winners);
  } else {
    SearchOrthants<4>(best, winners);
  }
}

bool KdTree::OutsideBox(const double* p) const {
  const Node& root = nodes_[0];
  for (std::size_t j = 0; j < static_cast<std::size_t>(dims_); ++j) {
    if (p[j] <= root.lo[j] || p[j] > root.hi[j]) return true;
  }
  return false;
}

std::uint32_t KdTree::ListedCell(const double* p) const {
  return dims_ == 3 ? grid_.ListedCell<3>(p) : OrthantGrid::kNoCell;
}

void KdTree::NearestPerOrthantInCell(std::uint32_t cell, const double* const* queries, int count,
                                     WinnerCube3* cubes) const {
  static_assert(kCellLanes == interp::kCellLanes);
  std::uint32_t begin = 0, entries = 0, need = 0;
  grid_.List(cell, begin, entries, need);
  const std::uint32_t* list = grid_.entry() + begin;
  const double* gap = grid_.block_gap() + begin / 8;
  const double* axis[3] = {axis_[0].data(), axis_[1].data(), axis_[2].data()};
#ifdef BRDF_KD_X86
  // A lone query scans faster on its own (ListAvx512 sends only its few candidates through the
  // exact rule; the lanes of the cell kernel would stand mostly idle).
  if (count > 1 && kernel_ == Kernel::kAvx512) {
    CellListAvx512(axis, rank_.data(), list, gap, entries / 8, need, queries, count, cubes);
    return;
  }
  if (count > 1 && kernel_ == Kernel::kAvx2 && rank_.size() - kPadding <= kCellAvx2Positions) {
    for (int first = 0; first < count; first += kCellLanesAvx2) {
      CellListAvx2(axis, rank_.data(), list, gap, entries / 8, need, queries + first,
                   std::min(kCellLanesAvx2, count - first), cubes + first);
    }
    return;
  }
#endif
  for (int k = 0; k < count; ++k) {
    OrthantBest best;
    best.q = {queries[k][0], queries[k][1], queries[k][2], 0.0};
    best.Clear();
    list_scan_(*this, list, gap, entries / 8, need, best);
    cubes[k].empty = 0;
    for (std::size_t o = 0; o < 8; ++o) PutCubeWinner(axis, rank_.data(), best.pos[o], o, cubes[k]);
  }
}

std::uint32_t KdTree::Nearest(const double* p) const {
  NearestBest best;
  if (dims_ == 3) {
    VisitNearest<3>(0, p, best);
  } else {
    VisitNearest<4>(0, p, best);
  }
  return best.rank;
}

}  // namespace brdf::interp
