// Interpolating scattered spectra: one interface, three methods (the paper's octant method,
// Delaunay through Qhull, nearest neighbour). Every answer carries its provenance: which samples
// were blended, where they are, with which weights, by which method, and whether it worked.
//
// Coordinates are (θi, θo, φ) for isotropic data (3D) or (θi, φi, θo, φo) for anisotropic data
// (4D), in degrees: samples and queries always come in these. Isotropic data may be interpolated
// in Rusinkiewicz's half/difference angles instead (Options.coordinates, half_difference.h).
// Pure: no I/O.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/status.h"

namespace brdf::interp {

enum class Method { kOctant, kDelaunay, kNearest };
const char* MethodName(Method m);  // "octant", "delaunay", "nearest"
Result<Method> ParseMethod(const std::string& name);

enum class InterpStatus {
  kOk,
  kEmptyOctant,         // octant method: an octant (orthant) around the query holds no sample
  kNoEnclosingSimplex,  // octant method: no tetrahedron (simplex) of the cube encloses the query
  kOutsideHull,         // Delaunay: the query lies outside the convex hull of the samples
};
const char* InterpStatusName(InterpStatus s);  // "ok", "empty_octant", ...

// The space a method measures distances and blends in. Samples and queries are given in
// (θi, θo, φ) either way. kHalfDifference (isotropic data only) maps every sample and query to
// (θh, θd, φd) first, where a specular lobe lies along the θh axis (half_difference.h).
enum class Coordinates { kIncidence, kHalfDifference };
const char* CoordinatesName(Coordinates c);  // "incidence", "half_difference"
// Accepts "incidence", "half_difference" and "half-diff" (the command lines' spelling).
Result<Coordinates> ParseCoordinates(const std::string& name);

// What a method blends (trend.h). kNone: the samples' spectra, as the paper does. kBivariate
// (isotropic data only): the residuals from a smooth trend T(θh, θd) fitted to all samples, T
// added back at the query.
enum class Trend { kNone, kBivariate };
const char* TrendName(Trend t);  // "none", "bivariate"
Result<Trend> ParseTrend(const std::string& name);

// Options shared by all methods.
struct Options {
  // Per-axis multipliers applied to coordinates before distances are measured (empty = all 1).
  // Raw degrees make φ span twice θ's range; scaling changes which neighbours win.
  std::vector<double> axis_scale;
  // Symmetry augmentation, isotropic (3D) data only. Both off by default: the paper's method as
  // published. mirror_phi adds (θi, θo, −φ) and (θi, θo, 360° − φ) for every sample (both exact:
  // the second fills the specular side, φ near 180°); reciprocity adds (θo, θi, φ) (and its
  // mirror images when both are on).
  // Augmented copies keep the id of the sample they copy and rank after all measured samples.
  bool mirror_phi = false;
  bool reciprocity = false;
  // kHalfDifference: interpolate in half/difference angles (3D data only), at the points
  // (θh·cos φd, θh·sin φd, θd); axis_scale then multiplies those three (default all 1); the
  // mirror images are always added there, reciprocity adds its own (half_difference.h).
  Coordinates coordinates = Coordinates::kIncidence;
  // kBivariate: blend residuals from a bivariate trend (trend.h; 3D data only). Works with either
  // coordinates.
  Trend trend = Trend::kNone;
};

// Scattered samples: N points of `dims` coordinates, each with a spectrum of `bands` values and
// an id (a reading id, or a CSV row index). Order matters: ties go to the earlier sample.
//
// Storage comes in chunks of kChunkSamples samples, shared between copies: copying a set copies
// one pointer per chunk, not the spectra, and Add on a copy writes into a chunk of its own (at
// most the last, partly filled one is copied first), so the original never changes. That makes
// "the readings so far plus one more" cheap while readers keep the set they had (the daemon's
// snapshots). A sample's coordinates and spectrum are contiguous; two samples' need not be.
class SampleSet {
 public:
  static constexpr std::size_t kChunkSamples = 128;

  SampleSet(int dims, int bands) : dims_(dims), bands_(bands) {}

  // Appends a sample; coords.size() == dims, spectrum.size() == bands.
  Status Add(std::int64_t id, std::span<const double> coords, std::span<const double> spectrum);

  int dims() const { return dims_; }
  int bands() const { return bands_; }
  std::size_t size() const { return size_; }
  std::int64_t id(std::size_t i) const {
    return chunks_[i / kChunkSamples]->ids[i % kChunkSamples];
  }
  std::span<const double> coords(std::size_t i) const {
    return {coords_[i / kChunkSamples] + (i % kChunkSamples) * static_cast<std::size_t>(dims_),
            static_cast<std::size_t>(dims_)};
  }
  std::span<const double> spectrum(std::size_t i) const {
    return {values_[i / kChunkSamples] + (i % kChunkSamples) * static_cast<std::size_t>(bands_),
            static_cast<std::size_t>(bands_)};
  }
  // Heap the set holds (its chunks, whoever else shares them, and its chunk tables), for memory
  // bounds.
  std::size_t HeapBytes() const;
  // True when sample i of both sets is stored once, in memory both share (for tests and for
  // callers that check that a set grew from another by Add).
  bool SharesStorageWith(const SampleSet& other, std::size_t i) const {
    return i < size_ && i < other.size_ &&
           chunks_[i / kChunkSamples] == other.chunks_[i / kChunkSamples];
  }

 private:
  // Up to kChunkSamples samples; its vectors are reserved in full when made, so they never move.
  struct Chunk {
    std::vector<std::int64_t> ids;
    std::vector<double> coords;  // ids.size() * dims
    std::vector<double> values;  // ids.size() * bands
  };

  int dims_;
  int bands_;
  std::size_t size_ = 0;
  // Shared with copies; a chunk is written only while this set is its one owner.
  std::vector<std::shared_ptr<Chunk>> chunks_;
  // chunks_[c]->coords.data() and ->values.data(): one load less on the way to a spectrum.
  std::vector<const double*> coords_;
  std::vector<const double*> values_;
};

// One blended vertex of an answer.
struct Vertex {
  std::int64_t id = 0;         // the sample's id
  std::size_t index = 0;       // the sample's position in the SampleSet
  std::vector<double> coords;  // where the vertex is (after symmetry augmentation, unscaled)
  double weight = 0;           // barycentric weight (nearest: 1)
};

struct Interpolation {
  Method method = Method::kOctant;
  InterpStatus status = InterpStatus::kOk;
  std::vector<double> spectrum;  // `bands` values when status == kOk, empty otherwise
  std::vector<Vertex> vertices;  // the blended samples (octant: 4 or 5; Delaunay: dims+1)
  std::string detail;            // e.g. which octant was empty, which tetrahedron enclosed
};

class Interpolator {
 public:
  virtual ~Interpolator() = default;
  virtual Method method() const = 0;
  virtual int dims() const = 0;
  // query.size() == dims(). Thread-safe (const): many threads may evaluate at once.
  virtual Interpolation Evaluate(std::span<const double> query) const = 0;
  // Heap the index holds beyond the SampleSet it was given: its copies of the coordinates (and
  // their symmetry images), its search tree or triangulation, and any sample set it made (the
  // half/difference images, the trend's residuals). For memory bounds (the daemon's caches);
  // within a few per cent of what the allocator hands out for them.
  virtual std::size_t HeapBytes() const = 0;

  // The same answer's status and spectrum only, for callers that need no provenance (batches,
  // grids, rendering): the spectrum is written into `spectrum` (the sample set's bands() values)
  // when the status is kOk and left untouched otherwise. Methods override it to answer without
  // allocating; this default goes through Evaluate. Thread-safe like Evaluate.
  virtual InterpStatus SpectrumAt(std::span<const double> query, std::span<double> spectrum) const {
    Interpolation r = Evaluate(query);
    if (r.status == InterpStatus::kOk) {
      std::copy_n(r.spectrum.begin(), std::min(r.spectrum.size(), spectrum.size()),
                  spectrum.begin());
    }
    return r.status;
  }

  // Receives answer `index` of an EvaluateEach; returns false to stop the batch there.
  using TakeAnswer = std::function<bool(std::size_t index, Interpolation&& answer)>;
  // Full answers (with provenance) for queries.size() / dims() queries (row-major), single
  // thread, each the answer Evaluate gives, handed to `take` in query order as they are ready, so
  // the caller can stream them without holding all of them; stops when `take` returns false.
  // Methods override it to answer a large batch faster (the octant method sorts it by cell); this
  // default calls Evaluate query by query.
  virtual void EvaluateEach(std::span<const double> queries, const TakeAnswer& take) const {
    const auto d = static_cast<std::size_t>(dims());
    for (std::size_t i = 0; i < queries.size() / d; ++i) {
      if (!take(i, Evaluate(queries.subspan(i * d, d)))) return;
    }
  }

  // Many queries in one call, single thread, in order: n = statuses.size() queries (row-major,
  // dims() coordinates each) answered as SpectrumAt would, statuses[i] and row i of `spectra`
  // (n × bands values; rows of queries that are not kOk are set to NaN). Methods override it to
  // overlap one query's memory traffic with the next one's search. The caller checks the sizes
  // (EvaluateSpectraBatch in batch.h does, and spreads a batch over threads).
  virtual void SpectraAt(std::span<const double> queries, std::span<InterpStatus> statuses,
                         std::span<double> spectra) const {
    const std::size_t n = statuses.size();
    if (n == 0) return;
    const auto d = static_cast<std::size_t>(dims());
    const std::size_t bands = spectra.size() / n;
    for (std::size_t i = 0; i < n; ++i) {
      const std::span<double> row = spectra.subspan(i * bands, bands);
      statuses[i] = SpectrumAt(queries.subspan(i * d, d), row);
      if (statuses[i] != InterpStatus::kOk) {
        std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
};

// Builds the index for `samples` (3D or 4D). Errors: wrong dims, empty set, bad options
// (e.g. symmetry options on 4D data, axis_scale of the wrong length or non-positive),
// Qhull failures (degenerate input) for Delaunay.
Result<std::unique_ptr<Interpolator>> MakeInterpolator(Method method,
                                                       std::shared_ptr<const SampleSet> samples,
                                                       const Options& options = {});

}  // namespace brdf::interp
