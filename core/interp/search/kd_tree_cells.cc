// The multi-query list kernel of KdTree::NearestPerOrthantInCell (search/kd_tree.h,
// search/kd_tree_cells.h).
//
// Why: one query's list scan (search/kd_tree.cc, ListAvx512) holds 8 list entries in its lanes and
// sends every entry that beats its orthant's best through the exact rule one by one; on the rig
// grid that is ~15 entries per query, each an unpredictable branch, and most of the query's
// time. Here the lanes hold up to 8 queries of the same cell instead: each list entry is
// broadcast to all of them, and every lane keeps its own 8 orthant bests: the distances in 8
// registers (one per orthant, lane k = query k), the points' tree positions in an 8 × 8 array
// beside them. An entry's distance and orthant per lane, the best of that orthant picked by three
// levels of blends, one compare, and masked moves (distances) and masked stores (positions): no
// branch per entry, whatever the entry does to any lane.
//
// Exactness: per lane the entries are offered in list order under the exact rule (nearer wins;
// at the same distance, the lower rank: the rare equal distances go through a vector path of
// their own), with OrthantOf's sides and SquaredDistance's operations in its order, so each
// lane ends with the lexicographic minimum of (distance, rank) over the entries it scanned. The
// scan stops at the first block whose distance bound (valid for every query of the cell) exceeds
// every lane's needed bests, which is where each lane's own scan could stop or later; entries
// scanned beyond it are points of the cloud, so they cannot change a minimum that already holds
// the winner. Same winners as NearestPerOrthant, bit for bit (tests/interp/).
// Pure: no I/O.
#include "core/interp/search/kd_tree_cells.h"

#include <cstdint>
#include <limits>

#include "core/interp/octant/cube.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

namespace brdf::interp {
namespace {

// The phases of CellListAvx512, inlined into it (its registers stay registers).
#define BRDF_AVX512_PHASE __attribute__((target("avx512f"), always_inline)) inline

constexpr int kOrthants3 = 8;

// Lane k holds query k's coordinates on axis j (lanes past count repeat query 0).
BRDF_AVX512_PHASE void LoadQueries512(const double* const* queries, int count, __m512d q[3]) {
  for (int j = 0; j < 3; ++j) {
    alignas(64) double lane[kCellLanes];
    for (int k = 0; k < kCellLanes; ++k) lane[k] = queries[k < count ? k : 0][j];
    q[j] = _mm512_load_pd(lane);
  }
}

// The entry at tree position pos against each lane's query: the squared distance and the side
// per axis (plus[j]: at or above the query), as OrthantOf and SquaredDistance compute them.
BRDF_AVX512_PHASE __m512d EntryDistance512(const double* const* axis, std::uint32_t pos,
                                           const __m512d q[3], __mmask8 plus[3]) {
  __m512d d2 = _mm512_setzero_pd();
#pragma GCC unroll 3
  for (int j = 0; j < 3; ++j) {
    const __m512d v = _mm512_set1_pd(axis[j][pos]);
    const __m512d diff = _mm512_sub_pd(v, q[j]);
    __m512d sq = _mm512_mul_pd(diff, diff);
    asm("" : "+v"(sq));  // no fused multiply-add: round the square first
    d2 = j == 0 ? sq : _mm512_add_pd(d2, sq);
    plus[j] = _mm512_cmp_pd_mask(v, q[j], _CMP_GE_OQ);
  }
  return d2;
}

// Each lane's best in the entry's orthant: bit 0 (θi) picks within pairs, then bit 1, bit 2.
BRDF_AVX512_PHASE __m512d BestInOrthant512(const __m512d best[kOrthants3], const __mmask8 plus[3]) {
  const __m512d b01 = _mm512_mask_blend_pd(plus[0], best[0], best[1]);
  const __m512d b23 = _mm512_mask_blend_pd(plus[0], best[2], best[3]);
  const __m512d b45 = _mm512_mask_blend_pd(plus[0], best[4], best[5]);
  const __m512d b67 = _mm512_mask_blend_pd(plus[0], best[6], best[7]);
  const __m512d b03 = _mm512_mask_blend_pd(plus[1], b01, b23);
  const __m512d b47 = _mm512_mask_blend_pd(plus[1], b45, b67);
  return _mm512_mask_blend_pd(plus[2], b03, b47);
}

// The entry's orthant per lane.
BRDF_AVX512_PHASE __m512i OrthantCode512(const __mmask8 plus[3]) {
  __m512i code = _mm512_maskz_mov_epi64(plus[0], _mm512_set1_epi64(1));
  code = _mm512_mask_add_epi64(code, plus[1], code, _mm512_set1_epi64(2));
  return _mm512_mask_add_epi64(code, plus[2], code, _mm512_set1_epi64(4));
}

// The lanes in `tie`, where the entry p (tree position) is as near as its orthant's best: at the
// same distance the lower rank wins; a lane's best met again (lists repeat their last entry as
// padding) has the same rank and stays.
BRDF_AVX512_PHASE void SettleTies512(__mmask8 tie, __m512i code, __m512i p, __m512i r,
                                     const std::uint32_t* rank,
                                     std::uint64_t at[kOrthants3][kCellLanes]) {
  for (int o = 0; o < kOrthants3; ++o) {
    const __mmask8 mine = _mm512_mask_cmpeq_epi64_mask(tie, code, _mm512_set1_epi64(o));
    if (mine == 0) continue;
    // An empty orthant (held position kNoPoint) ties only with an infinite distance, and
    // takes it, as the exact rule does.
    const __m512i at_o = _mm512_load_epi64(at[o]);
    const __mmask8 empty = _mm512_mask_cmpeq_epi64_mask(mine, at_o, _mm512_set1_epi64(kNoPoint));
    const auto held_lanes = static_cast<__mmask8>(mine & ~empty);
    const __m512i held = _mm512_cvtepu32_epi64(
        _mm512_mask_i64gather_epi32(_mm256_setzero_si256(), held_lanes, at_o, rank, 4));
    _mm512_mask_store_epi64(
        at[o], static_cast<__mmask8>(empty | _mm512_mask_cmplt_epu64_mask(held_lanes, r, held)), p);
  }
}

// The largest needed best over the active lanes (orthants outside `need` are empty for every
// query of the cell and would keep +inf).
BRDF_AVX512_PHASE double WorstNeeded512(const __m512d best[kOrthants3],
                                        const __mmask8 needed[kOrthants3], __mmask8 active) {
  __m512d m = _mm512_set1_pd(-std::numeric_limits<double>::infinity());
#pragma GCC unroll 8
  for (int o = 0; o < kOrthants3; ++o) m = _mm512_mask_max_pd(m, needed[o], m, best[o]);
  return _mm512_mask_reduce_max_pd(active, m);
}

// Query k's winners are column k of the orthant registers: store them, then gather each
// column's positions, and through them the winners' coordinates and ranks.
BRDF_AVX512_PHASE void StoreCubes512(const std::uint64_t at[kOrthants3][kCellLanes],
                                     const double* const* axis, const std::uint32_t* rank,
                                     int count, WinnerCube3* cubes) {
  alignas(64) std::uint32_t pos[kOrthants3][kCellLanes];
  for (int o = 0; o < kOrthants3; ++o) {
    _mm512_mask_cvtepi64_storeu_epi32(pos[o], 0xFF, _mm512_load_epi64(at[o]));
  }
  const __m256i column = _mm256_setr_epi32(0, 8, 16, 24, 32, 40, 48, 56);
  const __m256i no_point = _mm256_set1_epi32(static_cast<int>(kNoPoint));
  for (int k = 0; k < count; ++k) {
    const __m256i at_k =
        _mm256_i32gather_epi32(reinterpret_cast<const int*>(&pos[0][k]), column, 4);
    const __m256i none_k = _mm256_cmpeq_epi32(at_k, no_point);
    const auto empty = static_cast<__mmask8>(_mm256_movemask_ps(_mm256_castsi256_ps(none_k)));
    const auto held = static_cast<__mmask8>(~empty);
    WinnerCube3& cube = cubes[k];
    cube.empty = empty;
    for (int j = 0; j < 3; ++j) {
      _mm512_store_pd(cube.axis[static_cast<std::size_t>(j)].data(),
                      _mm512_mask_i32gather_pd(_mm512_setzero_pd(), held, at_k, axis[j], 8));
    }
    _mm256_storeu_si256(
        reinterpret_cast<__m256i*>(cube.rank.data()),
        _mm256_mask_i32gather_epi32(no_point, reinterpret_cast<const int*>(rank), at_k,
                                    _mm256_xor_si256(none_k, _mm256_set1_epi32(-1)), 4));
  }
}

#undef BRDF_AVX512_PHASE

}  // namespace

__attribute__((target("avx512f"))) void CellListAvx512(
    const double* const* axis, const std::uint32_t* rank, const std::uint32_t* entry,
    const double* block_gap, std::uint32_t blocks, unsigned need, const double* const* queries,
    int count, WinnerCube3* cubes) {
  constexpr int kOrthants = kOrthants3;
  const auto active = static_cast<__mmask8>((1u << count) - 1u);
  __m512d q[3];
  LoadQueries512(queries, count, q);
  // Per orthant, each lane's best distance (registers) and the tree position of that best point
  // (memory: 8 more registers would not fit beside the others; masked stores cost little).
  __m512d best[kOrthants];
  alignas(64) std::uint64_t at[kOrthants][kCellLanes];
  __mmask8 needed[kOrthants];
#pragma GCC unroll 8
  for (int o = 0; o < kOrthants; ++o) {
    best[o] = _mm512_set1_pd(std::numeric_limits<double>::infinity());
    _mm512_store_epi64(at[o], _mm512_set1_epi64(kNoPoint));
    needed[o] = static_cast<__mmask8>(((need >> o) & 1u) != 0 ? 0xFF : 0);
  }
  double worst = std::numeric_limits<double>::infinity();
  for (std::uint32_t b = 0; b < blocks; ++b) {
    if (block_gap[b] > worst) break;
#pragma GCC unroll 2
    for (std::uint32_t e = 0; e < 8; ++e) {
      const std::uint32_t pos = entry[std::size_t{b} * 8 + e];
      __mmask8 plus[3];
      const __m512d d2 = EntryDistance512(axis, pos, q, plus);
      const __m512d limit = BestInOrthant512(best, plus);
      const __mmask8 nearer = _mm512_mask_cmp_pd_mask(active, d2, limit, _CMP_LT_OQ);
      const __mmask8 tie = _mm512_mask_cmp_pd_mask(active, d2, limit, _CMP_EQ_OQ);
      // The lanes where the entry is nearer than its orthant's best take it.
      const __m512i code = OrthantCode512(plus);
      const __m512i p = _mm512_set1_epi64(pos);
#pragma GCC unroll 8
      for (int o = 0; o < kOrthants; ++o) {
        const __mmask8 won = _mm512_mask_cmpeq_epi64_mask(nearer, code, _mm512_set1_epi64(o));
        best[o] = _mm512_mask_mov_pd(best[o], won, d2);
        _mm512_mask_store_epi64(at[o], won, p);
      }
      if (tie != 0) SettleTies512(tie, code, p, _mm512_set1_epi64(rank[pos]), rank, at);
    }
    worst = WorstNeeded512(best, needed, active);
  }
  StoreCubes512(at, axis, rank, count, cubes);
}

// The AVX2 variant: 4 queries per register, and 16 registers in all, too few for 8 bests and 8
// positions per lane. So each lane's best per orthant is one 64-bit key: the squared distance's
// bits (a non-negative double's bits order like the double) with the low kPositionBits replaced
// by the tree position. Keys compare as integers; when two keys agree above those bits, their
// distances are within 2^-38 of each other relatively (a tie, or nearly), and the exact rule
// decides lane by lane from the exact distances (recomputed for the held point) and ranks.
namespace {

constexpr int kLanesAvx2 = 4;
constexpr int kPositionBits = 14;
constexpr std::int64_t kPositionMask = (std::int64_t{1} << kPositionBits) - 1;
// An empty orthant: +inf with every position bit set, above every finite distance's key.
constexpr std::int64_t kEmptyKey = 0x7FF0000000000000 | kPositionMask;

// The phases of CellListAvx2, inlined into it.
#define BRDF_AVX2_PHASE __attribute__((target("avx2"), always_inline)) inline

// b where m is set, else a (lane by lane).
BRDF_AVX2_PHASE __m256i Pick(__m256i a, __m256i b, __m256d m) {
  return _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b), m));
}

// Lane k holds query k's coordinates on axis j (lanes past count repeat query 0).
BRDF_AVX2_PHASE void LoadQueriesAvx2(const double* const* queries, int count, __m256d q[3]) {
  for (int j = 0; j < 3; ++j) {
    alignas(32) double lane[kLanesAvx2];
    for (int k = 0; k < kLanesAvx2; ++k) lane[k] = queries[k < count ? k : 0][j];
    q[j] = _mm256_load_pd(lane);
  }
}

// The entry at tree position pos against each lane's query: the squared distance and the side
// per axis (plus[j]: all ones at or above the query), as OrthantOf and SquaredDistance compute.
BRDF_AVX2_PHASE __m256d EntryDistanceAvx2(const double* const* axis, std::uint32_t pos,
                                          const __m256d q[3], __m256d plus[3]) {
  __m256d d2 = _mm256_setzero_pd();
#pragma GCC unroll 3
  for (int j = 0; j < 3; ++j) {
    const __m256d v = _mm256_broadcast_sd(axis[j] + pos);
    const __m256d diff = _mm256_sub_pd(v, q[j]);
    __m256d sq = _mm256_mul_pd(diff, diff);
    asm("" : "+x"(sq));  // no fused multiply-add: round the square first
    d2 = j == 0 ? sq : _mm256_add_pd(d2, sq);
    plus[j] = _mm256_cmp_pd(v, q[j], _CMP_GE_OQ);
  }
  return d2;
}

// Each lane's held key in the entry's orthant (bit 0 picks within pairs, then 1, then 2).
BRDF_AVX2_PHASE __m256i HeldKeyAvx2(const __m256i key[kOrthants3], const __m256d plus[3]) {
  return Pick(Pick(Pick(key[0], key[1], plus[0]), Pick(key[2], key[3], plus[0]), plus[1]),
              Pick(Pick(key[4], key[5], plus[0]), Pick(key[6], key[7], plus[0]), plus[1]), plus[2]);
}

// The entry's orthant per lane.
BRDF_AVX2_PHASE __m256i OrthantCodeAvx2(const __m256d plus[3]) {
  return _mm256_or_si256(
      _mm256_and_si256(_mm256_castpd_si256(plus[0]), _mm256_set1_epi64x(1)),
      _mm256_or_si256(_mm256_and_si256(_mm256_castpd_si256(plus[1]), _mm256_set1_epi64x(2)),
                      _mm256_and_si256(_mm256_castpd_si256(plus[2]), _mm256_set1_epi64x(4))));
}

// The lanes in `closes` (held key h and the entry's agree above the position bits): the exact
// rule between the held point and the entry pos, at distance d2, lane by lane. All ones in the
// lanes the entry takes.
BRDF_AVX2_PHASE __m256i DecideCloseAvx2(unsigned closes, __m256i h, __m256d d2,
                                        const double* const* axis, const std::uint32_t* rank,
                                        std::uint32_t pos, const double* const* queries) {
  alignas(32) std::int64_t held[kLanesAvx2];
  alignas(32) double dist[kLanesAvx2];
  _mm256_store_si256(reinterpret_cast<__m256i*>(held), h);
  _mm256_store_pd(dist, d2);
  alignas(32) std::int64_t take[kLanesAvx2] = {0, 0, 0, 0};
  for (; closes != 0; closes &= closes - 1) {
    const int lane = __builtin_ctz(closes);
    if (held[lane] == kEmptyKey) {  // an infinite distance into an empty orthant
      take[lane] = -1;
      continue;
    }
    const auto at = static_cast<std::uint32_t>(held[lane] & kPositionMask);
    double held_d2 = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double diff = axis[j][at] - queries[lane][j];
      double sq = diff * diff;
      asm("" : "+x"(sq));
      held_d2 = j == 0 ? sq : held_d2 + sq;
    }
    const bool better = dist[lane] < held_d2 || (dist[lane] == held_d2 && rank[pos] < rank[at]);
    take[lane] = better ? -1 : 0;
  }
  return _mm256_load_si256(reinterpret_cast<const __m256i*>(take));
}

// The largest needed best over the lanes, from above: a key with its position bits set is at
// or above its distance, and at most +inf's bits once capped (lanes past count repeat query
// 0). As integers: the keys of non-negative doubles order like them.
BRDF_AVX2_PHASE double WorstNeededAvx2(const __m256i key[kOrthants3], unsigned need) {
  const __m256i position_mask = _mm256_set1_epi64x(kPositionMask);
  const __m256i inf_bits = _mm256_set1_epi64x(0x7FF0000000000000);
  __m256i m = _mm256_setzero_si256();
#pragma GCC unroll 8
  for (int o = 0; o < kOrthants3; ++o) {
    if (((need >> o) & 1u) != 0) {
      const __m256i up = _mm256_or_si256(key[o], position_mask);
      m = Pick(m, up, _mm256_castsi256_pd(_mm256_cmpgt_epi64(up, m)));
    }
  }
  m = Pick(m, inf_bits, _mm256_castsi256_pd(_mm256_cmpgt_epi64(m, inf_bits)));
  const __m256d bound = _mm256_castsi256_pd(m);
  const __m128d h = _mm_max_pd(_mm256_castpd256_pd128(bound), _mm256_extractf128_pd(bound, 1));
  return _mm_cvtsd_f64(_mm_max_sd(h, _mm_unpackhi_pd(h, h)));
}

// Each lane's winners from its keys.
BRDF_AVX2_PHASE void StoreCubesAvx2(const __m256i key[kOrthants3], const double* const* axis,
                                    const std::uint32_t* rank, int count, WinnerCube3* cubes) {
  alignas(32) std::int64_t keys[kOrthants3][kLanesAvx2];
  for (int o = 0; o < kOrthants3; ++o) {
    _mm256_store_si256(reinterpret_cast<__m256i*>(keys[o]), key[o]);
  }
  for (int lane = 0; lane < count; ++lane) {
    cubes[lane].empty = 0;
    for (std::size_t o = 0; o < kOrthants3; ++o) {
      const std::int64_t held = keys[o][lane];
      const auto at =
          held == kEmptyKey ? kNoPoint : static_cast<std::uint32_t>(held & kPositionMask);
      PutCubeWinner(axis, rank, at, o, cubes[lane]);
    }
  }
}

#undef BRDF_AVX2_PHASE

}  // namespace

__attribute__((target("avx2"))) void CellListAvx2(const double* const* axis,
                                                  const std::uint32_t* rank,
                                                  const std::uint32_t* entry,
                                                  const double* block_gap, std::uint32_t blocks,
                                                  unsigned need, const double* const* queries,
                                                  int count, WinnerCube3* cubes) {
  constexpr int kOrthants = kOrthants3;
  __m256d q[3];
  LoadQueriesAvx2(queries, count, q);
  const __m256i position_mask = _mm256_set1_epi64x(kPositionMask);
  const __m256i position_limit = _mm256_set1_epi64x(kPositionMask + 1);
  const __m256i zero = _mm256_setzero_si256();
  __m256i key[kOrthants];
#pragma GCC unroll 8
  for (int o = 0; o < kOrthants; ++o) key[o] = _mm256_set1_epi64x(kEmptyKey);
  double worst = std::numeric_limits<double>::infinity();
  for (std::uint32_t b = 0; b < blocks; ++b) {
    if (block_gap[b] > worst) break;
    for (std::uint32_t e = 0; e < 8; ++e) {
      const std::uint32_t pos = entry[std::size_t{b} * 8 + e];
      __m256d plus[3];
      const __m256d d2 = EntryDistanceAvx2(axis, pos, q, plus);
      const __m256i k = _mm256_or_si256(_mm256_andnot_si256(position_mask, _mm256_castpd_si256(d2)),
                                        _mm256_set1_epi64x(pos));
      const __m256i h = HeldKeyAvx2(key, plus);
      const __m256i x = _mm256_xor_si256(k, h);
      // Keys that agree above the position bits but are not the same point: decide exactly.
      const __m256i close =
          _mm256_andnot_si256(_mm256_cmpeq_epi64(x, zero), _mm256_cmpgt_epi64(position_limit, x));
      const __m256i nearer = _mm256_andnot_si256(close, _mm256_cmpgt_epi64(h, k));
      const __m256i code = OrthantCodeAvx2(plus);
      unsigned closes = static_cast<unsigned>(_mm256_movemask_pd(_mm256_castsi256_pd(close)));
      closes &= (1u << count) - 1u;
      __m256i wins = nearer;
      if (closes != 0) {
        wins = _mm256_or_si256(wins, DecideCloseAvx2(closes, h, d2, axis, rank, pos, queries));
      }
#pragma GCC unroll 8
      for (int o = 0; o < kOrthants; ++o) {
        const __m256d won = _mm256_castsi256_pd(
            _mm256_and_si256(wins, _mm256_cmpeq_epi64(code, _mm256_set1_epi64x(o))));
        key[o] = Pick(key[o], k, won);
      }
    }
    worst = WorstNeededAvx2(key, need);
  }
  StoreCubesAvx2(key, axis, rank, count, cubes);
}

}  // namespace brdf::interp

#endif
