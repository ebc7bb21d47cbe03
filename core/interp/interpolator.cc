// The small, method-independent parts of interpolator.h: names, parsing, and SampleSet::Add.
#include "core/interp/interpolator.h"

#include <cmath>

namespace brdf::interp {

const char* MethodName(Method m) {
  switch (m) {
    case Method::kOctant:
      return "octant";
    case Method::kDelaunay:
      return "delaunay";
    case Method::kNearest:
      return "nearest";
  }
  return "unknown";
}

Result<Method> ParseMethod(const std::string& name) {
  for (Method m : {Method::kOctant, Method::kDelaunay, Method::kNearest}) {
    if (name == MethodName(m)) return m;
  }
  return InvalidArgument("unknown interpolation method '" + name +
                         "'; use one of: octant, delaunay, nearest");
}

const char* CoordinatesName(Coordinates c) {
  return c == Coordinates::kHalfDifference ? "half_difference" : "incidence";
}

Result<Coordinates> ParseCoordinates(const std::string& name) {
  if (name == "incidence") return Coordinates::kIncidence;
  if (name == "half_difference" || name == "half-diff") return Coordinates::kHalfDifference;
  return InvalidArgument("unknown coordinates '" + name +
                         "'; use incidence (θi, θo, φ) or half-diff (θh, θd, φd)");
}

const char* TrendName(Trend t) {
  return t == Trend::kBivariate ? "bivariate" : "none";
}

Result<Trend> ParseTrend(const std::string& name) {
  if (name == "none") return Trend::kNone;
  if (name == "bivariate") return Trend::kBivariate;
  return InvalidArgument("unknown trend '" + name +
                         "'; use none (blend the spectra) or bivariate (blend the residuals from "
                         "a fitted T(θh, θd))");
}

const char* InterpStatusName(InterpStatus s) {
  switch (s) {
    case InterpStatus::kOk:
      return "ok";
    case InterpStatus::kEmptyOctant:
      return "empty_octant";
    case InterpStatus::kNoEnclosingSimplex:
      return "no_enclosing_simplex";
    case InterpStatus::kOutsideHull:
      return "outside_hull";
  }
  return "unknown";
}

std::size_t SampleSet::HeapBytes() const {
  std::size_t bytes = (chunks_.capacity() * sizeof(chunks_[0])) +
                      (coords_.capacity() + values_.capacity()) * sizeof(const double*);
  for (const auto& chunk : chunks_) {
    bytes += sizeof(Chunk) + chunk->ids.capacity() * sizeof(std::int64_t) +
             (chunk->coords.capacity() + chunk->values.capacity()) * sizeof(double);
  }
  return bytes;
}

Status SampleSet::Add(std::int64_t id, std::span<const double> coords,
                      std::span<const double> spectrum) {
  const std::string where = "sample " + std::to_string(size()) + " (id " + std::to_string(id) + ")";
  if (dims_ != 3 && dims_ != 4) {
    return InvalidArgument(where + ": the set was made for " + std::to_string(dims_) +
                           " coordinates; interpolation needs 3 (θi, θo, φ) or 4 (θi, φi, θo, φo)");
  }
  if (bands_ < 1) {
    return InvalidArgument(where + ": the set was made for " + std::to_string(bands_) +
                           " bands; a spectrum needs at least one");
  }
  if (coords.size() != static_cast<std::size_t>(dims_)) {
    return InvalidArgument(where + " has " + std::to_string(coords.size()) +
                           " coordinates; this set holds " + std::to_string(dims_));
  }
  if (spectrum.size() != static_cast<std::size_t>(bands_)) {
    return InvalidArgument(where + " has " + std::to_string(spectrum.size()) +
                           " spectral values; this set holds " + std::to_string(bands_));
  }
  for (std::size_t j = 0; j < coords.size(); ++j) {
    if (!std::isfinite(coords[j])) {
      return InvalidArgument(where + ": coordinate " + std::to_string(j) +
                             " is not a finite number; drop or fix the reading");
    }
  }
  for (std::size_t b = 0; b < spectrum.size(); ++b) {
    if (!std::isfinite(spectrum[b])) {
      return InvalidArgument(where + ": spectral value " + std::to_string(b) +
                             " is not a finite number; drop or fix the reading");
    }
  }
  // Indices are 32-bit inside the search index (with up to four symmetry copies per sample).
  if (size() >= (std::size_t{1} << 29)) {
    return InvalidArgument(where + ": too many samples (the limit is 2^29)");
  }
  auto new_chunk = [this] {
    auto chunk = std::make_shared<Chunk>();
    chunk->ids.reserve(kChunkSamples);
    chunk->coords.reserve(kChunkSamples * static_cast<std::size_t>(dims_));
    chunk->values.reserve(kChunkSamples * static_cast<std::size_t>(bands_));
    return chunk;
  };
  if (size_ % kChunkSamples == 0) {
    chunks_.push_back(new_chunk());
    coords_.push_back(nullptr);
    values_.push_back(nullptr);
  } else if (chunks_.back().use_count() > 1) {
    // Another set (a copy, or the set this one was copied from) reads this chunk: write into a
    // copy of it. Only this set can raise the count of a chunk it alone holds, so a count of 1
    // means nobody else can see the write.
    std::shared_ptr<Chunk> chunk = new_chunk();
    const Chunk& shared = *chunks_.back();
    chunk->ids.assign(shared.ids.begin(), shared.ids.end());
    chunk->coords.assign(shared.coords.begin(), shared.coords.end());
    chunk->values.assign(shared.values.begin(), shared.values.end());
    chunks_.back() = std::move(chunk);
  }
  Chunk& chunk = *chunks_.back();
  chunk.ids.push_back(id);
  chunk.coords.insert(chunk.coords.end(), coords.begin(), coords.end());
  chunk.values.insert(chunk.values.end(), spectrum.begin(), spectrum.end());
  coords_.back() = chunk.coords.data();
  values_.back() = chunk.values.data();
  ++size_;
  return Status::Ok();
}

}  // namespace brdf::interp
