#include "daemon/api/interpolation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry.h"
#include "daemon/api/interpolation_uncertainty.h"
#include "daemon/index/build.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {

InterpolationService::InterpolationService(IndexCache& cache, const Authenticator& auth,
                                           const StopSignal& stopping, StreamRegistry& streams)
    : cache_(cache), auth_(auth), stopping_(stopping), streams_(streams) {}

namespace {

// The documented ranges (brdf.proto: IsoDirection, Directions, DirectionQuery). A relative
// azimuth outside [0, 180] is refused: it is a caller's mix-up of conventions, not a point. An
// azimuth of the four-angle form is periodic: any value in [−360, 360] names the same direction as
// its remainder in (−180, 180] and is taken so.
constexpr double kThetaMax = 90;
constexpr double kRelativePhiMax = 180;
constexpr double kAzimuthLimit = 360;
constexpr const char* kThetaHint = "a polar angle from the sample normal; give 0 to 90";
constexpr const char* kRelativePhiHint =
    "the relative azimuth |φo − φi| folded into [0, 180] (180: the specular side, 0: the retro "
    "side); give −φ for a negative φ, 360 − φ for one above 180, or use the four-angle form";
constexpr const char* kAzimuthHint =
    "an azimuth; give −360 to 360 (taken modulo 360 into (−180, 180])";

struct Settings {
  interp::Method method = interp::Method::kOctant;
  Quantity quantity = Quantity::kBrdf;
  interp::Options options;
};

grpc::Status ParseSettings(int method, int quantity, const v1::InterpolationOptions& options,
                           Settings* out) {
  if (grpc::Status st = ParseMethodField(method, &out->method); !st.ok()) return st;
  if (grpc::Status st = ParseQuantityField(quantity, &out->quantity); !st.ok()) return st;
  return ParseInterpolationOptions(options, &out->options);
}

// Ranges and finiteness, independent of the session. `field` is the DirectionQuery's path.
grpc::Status CheckDirection(const QueryAngles& q, const std::string& field) {
  // The field's name is only put together for an error (a valid query costs no allocation).
  auto check = [&field](double v, double lo, double hi, const char* suffix, const char* hint) {
    if (std::isfinite(v) && v >= lo && v <= hi) return grpc::Status::OK;
    const Status st = CheckAngle(v, lo, hi, field + suffix);
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        BoundedMessage(st.message() + ": " + hint));
  };
  const std::array<double, 4>& a = q.angles;
  grpc::Status st;
  switch (q.form) {
    case v1::DirectionQuery::kIso:
      if (st = check(a[0], 0, kThetaMax, ".iso.theta_i", kThetaHint); !st.ok()) return st;
      if (st = check(a[1], 0, kThetaMax, ".iso.theta_o", kThetaHint); !st.ok()) return st;
      return check(a[2], 0, kRelativePhiMax, ".iso.phi", kRelativePhiHint);
    case v1::DirectionQuery::kFour:
      if (st = check(a[0], 0, kThetaMax, ".four.theta_i", kThetaHint); !st.ok()) return st;
      if (st = check(a[1], -kAzimuthLimit, kAzimuthLimit, ".four.phi_i", kAzimuthHint); !st.ok())
        return st;
      if (st = check(a[2], 0, kThetaMax, ".four.theta_o", kThetaHint); !st.ok()) return st;
      return check(a[3], -kAzimuthLimit, kAzimuthLimit, ".four.phi_o", kAzimuthHint);
    case v1::DirectionQuery::DIRECTION_NOT_SET:
      break;
  }
  return InvalidField(field, "no direction; set iso (θi, θo, φ) or four (θi, φi, θo, φo)");
}

// (−180, 180], the range of the stored azimuths.
double WrapAzimuth(double phi) {
  double w = std::fmod(phi, 360.0);
  if (w <= -180) w += 360;
  if (w > 180) w -= 360;
  return w;
}

// The query in the index's coordinates.
grpc::Status ToCoords(const QueryAngles& q, const IndexSnapshot& index, const std::string& field,
                      std::array<double, 4>* coords) {
  const std::array<double, 4>& a = q.angles;
  if (index.anisotropic) {
    if (q.form != v1::DirectionQuery::kFour) {
      return InvalidField(field + ".iso", "session " + std::to_string(index.session) +
                                              " is anisotropic; give four angles (" + field +
                                              ".four: θi, φi, θo, φo)");
    }
    *coords = {a[0], WrapAzimuth(a[1]), a[2], WrapAzimuth(a[3])};
    return grpc::Status::OK;
  }
  IsoDirection iso;
  if (q.form == v1::DirectionQuery::kFour) {
    iso = ToIsotropic(Directions{a[0], a[1], a[2], a[3]});
  } else {
    // φ is in [0, 180] (CheckDirection); φ = 0 at the normal, exactly as the readings were
    // reduced.
    iso = ToIsotropic(CanonicalDirections(IsoDirection{a[0], a[1], a[2]}));
  }
  *coords = {iso.theta_i, iso.theta_o, iso.phi, 0};
  return grpc::Status::OK;
}

// Whether each vertex carries its sample's spectrum (InterpolateRequest.include_vertex_spectra).
enum class VertexSpectra { kOmit, kInclude };
// Which parts of its uncertainty the answer carries; none: not asked (include_uncertainty).
using WithUncertainty = std::optional<UncertaintyParts>;

// One answer as the API gives it.
void ToResult(const QueryAngles& query, interp::Interpolation&& r, const Settings& settings,
              const IndexSnapshot& index, VertexSpectra vertex_spectra,
              WithUncertainty with_uncertainty, v1::InterpolationResult* out) {
  ToQuery(query, out->mutable_query());
  if (with_uncertainty) AddInterpolationUncertainty(r, index, *with_uncertainty, out);
  out->set_status(ToProtoInterpStatus(r.status));
  out->set_method(ToProtoMethod(r.method));
  out->set_quantity(ToProtoQuantity(settings.quantity));
  *out->mutable_grid() = ToProtoGrid(index.grid);
  out->mutable_spectrum()->Add(r.spectrum.begin(), r.spectrum.end());
  for (const interp::Vertex& v : r.vertices) {
    v1::InterpolationVertex* vertex = out->add_vertices();
    vertex->set_reading_id(v.id);
    vertex->mutable_coords()->Add(v.coords.begin(), v.coords.end());
    vertex->set_weight(v.weight);
    if (vertex_spectra == VertexSpectra::kInclude) {
      // The sample the vertex blends, from the snapshot the answer came from (v.index is its
      // position in that set), in the answer's quantity.
      const std::span<const double> spectrum = index.samples->spectrum(v.index);
      vertex->mutable_spectrum()->Add(spectrum.begin(), spectrum.end());
    }
  }
  std::string detail = std::move(r.detail);
  if (index.skipped > 0) {
    detail += (detail.empty() ? "" : "; ") + std::to_string(index.skipped) +
              " sample reading(s) of the session left out (first: " + index.skipped_detail + ")";
  }
  out->set_detail(std::move(detail));
}

void Evaluate(const QueryAngles& query, const std::array<double, 4>& coords,
              const Settings& settings, const IndexSnapshot& index, VertexSpectra vertex_spectra,
              WithUncertainty with_uncertainty, v1::InterpolationResult* out) {
  ToResult(query,
           index.interpolator->Evaluate(
               std::span<const double>(coords.data(), static_cast<std::size_t>(index.dims))),
           settings, index, vertex_spectra, with_uncertainty, out);
}

grpc::Status SessionOf(const std::string& text, SessionId* id) {
  Result<SessionId> parsed = ParseSessionId(text, "session_id");
  if (!parsed.ok()) return ToGrpcStatus(parsed.status());
  *id = *parsed;
  return grpc::Status::OK;
}

}  // namespace

grpc::Status ParseInterpolationOptions(const v1::InterpolationOptions& options,
                                       interp::Options* out) {
  if (options.axis_scale_size() > 4) {
    return InvalidField("options.axis_scale", "at most 4 values (one per axis), got " +
                                                  std::to_string(options.axis_scale_size()));
  }
  for (int i = 0; i < options.axis_scale_size(); ++i) {
    const double s = options.axis_scale(i);
    if (!std::isfinite(s) || s <= 0) {
      return InvalidField("options.axis_scale[" + std::to_string(i) + "]",
                          "must be a finite number > 0 (got " + std::to_string(s) + ")");
    }
  }
  out->axis_scale.assign(options.axis_scale().begin(), options.axis_scale().end());
  out->mirror_phi = options.mirror_phi();
  out->reciprocity = options.reciprocity();
  if (grpc::Status st = ParseTrendField(options.trend(), &out->trend); !st.ok()) return st;
  return ParseCoordinatesField(options.coordinates(), &out->coordinates);
}

grpc::Status CheckOptionsFit(const interp::Options& options, const IndexSnapshot& index) {
  // The cache keys all-1 scales as none, so a hit does not tell that their count fits.
  return ToGrpcStatus(CheckIndexOptions(options, index.dims, index.session));
}

std::optional<grpc::Status> InterpolationService::AnswerIfReady(
    const v1::InterpolateRequest& request, v1::InterpolateResponse* response) {
  return Respond(request, response, /*may_load=*/false);
}

grpc::Status InterpolationService::Answer(const v1::InterpolateRequest& request,
                                          v1::InterpolateResponse* response) {
  return *Respond(request, response, /*may_load=*/true);
}

std::optional<grpc::Status> InterpolationService::Respond(const v1::InterpolateRequest& request,
                                                          v1::InterpolateResponse* response,
                                                          bool may_load) {
  SessionId id = 0;
  if (grpc::Status st = SessionOf(request.session_id(), &id); !st.ok()) return st;
  Settings settings;
  if (grpc::Status st =
          ParseSettings(request.method(), request.quantity(), request.options(), &settings);
      !st.ok()) {
    return st;
  }
  const QueryAngles direction = AnglesOf(request.direction());
  if (grpc::Status st = CheckDirection(direction, "direction"); !st.ok()) return st;

  std::shared_ptr<const IndexSnapshot> index;
  if (may_load) {
    Result<std::shared_ptr<const IndexSnapshot>> loaded =
        cache_.Get(id, settings.quantity, settings.method, settings.options);
    if (!loaded.ok()) return ToGrpcStatus(loaded.status());
    index = *std::move(loaded);
  } else {
    index = cache_.FreshHit(id, settings.quantity, settings.method, settings.options);
    if (!index) return std::nullopt;
  }
  if (grpc::Status st = CheckOptionsFit(settings.options, *index); !st.ok()) return st;
  std::array<double, 4> coords{};
  if (grpc::Status st = ToCoords(direction, *index, "direction", &coords); !st.ok()) return st;
  Evaluate(direction, coords, settings, *index,
           request.include_vertex_spectra() ? VertexSpectra::kInclude : VertexSpectra::kOmit,
           request.include_uncertainty() ? WithUncertainty(UncertaintyParts{}) : std::nullopt,
           response->mutable_result());
  return grpc::Status::OK;
}

namespace {

// An InterpolateBatch request checked before any index is asked: the session, the settings, the
// directions' count and ranges, and the results per chunk.
grpc::Status CheckBatch(const BatchRequest& batch, SessionId* id, Settings* settings, int* chunk) {
  const v1::InterpolateBatchRequest& request = batch.settings;
  if (grpc::Status st = SessionOf(request.session_id(), id); !st.ok()) return st;
  if (grpc::Status st =
          ParseSettings(request.method(), request.quantity(), request.options(), settings);
      !st.ok()) {
    return st;
  }
  const int n = static_cast<int>(batch.directions.size());
  if (n == 0)
    return InvalidField("directions",
                        "empty; give 1 to " + std::to_string(kMaxBatchDirections) + " directions");
  if (n > kMaxBatchDirections) {
    // A limit of the server, not a malformed request: RESOURCE_EXHAUSTED, as for an oversized
    // message.
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        "directions: " + std::to_string(n) + " directions; at most " +
                            std::to_string(kMaxBatchDirections) +
                            " per InterpolateBatch (split the request into several batches)");
  }
  if (request.chunk_size() > kMaxChunkSize) {
    return InvalidField("chunk_size", std::to_string(request.chunk_size()) +
                                          " results per chunk; at most " +
                                          std::to_string(kMaxChunkSize) +
                                          " (0: " + std::to_string(kDefaultChunkSize) + ")");
  }
  if (request.include_uncertainty() && request.chunk_size() > kMaxUncertainChunkSize) {
    return InvalidField("chunk_size", std::to_string(request.chunk_size()) +
                                          " results per chunk with include_uncertainty; at most " +
                                          std::to_string(kMaxUncertainChunkSize) +
                                          " (each result carries more spectra)");
  }
  *chunk = static_cast<int>(request.chunk_size() == 0 ? kDefaultChunkSize : request.chunk_size());
  for (int i = 0; i < n; ++i) {
    if (grpc::Status st = CheckDirection(batch.directions[static_cast<std::size_t>(i)],
                                         "directions[" + std::to_string(i) + "]");
        !st.ok()) {
      return st;
    }
  }
  return grpc::Status::OK;
}

// Directions [first, first + count) of the batch in the index's coordinates, row-major (the
// index's dims per row).
grpc::Status BatchCoords(const BatchRequest& request, const IndexSnapshot& index, int first,
                         int count, std::vector<double>* coords) {
  const auto d = static_cast<std::size_t>(index.dims);
  coords->assign(static_cast<std::size_t>(count) * d, 0);
  for (int k = 0; k < count; ++k) {
    const int i = first + k;
    std::array<double, 4> at{};
    if (grpc::Status st = ToCoords(request.directions[static_cast<std::size_t>(i)], index,
                                   "directions[" + std::to_string(i) + "]", &at);
        !st.ok()) {
      return st;
    }
    std::copy_n(at.begin(), d, coords->begin() + static_cast<std::ptrdiff_t>(k * d));
  }
  return grpc::Status::OK;
}

// Every direction of the batch checked against the session, a slice at a time, so that a bad
// one is refused before the first result goes out.
grpc::Status CheckBatchDirections(const BatchRequest& request, const IndexSnapshot& index,
                                  int slice) {
  const int n = static_cast<int>(request.directions.size());
  std::vector<double> probe;
  for (int first = 0; first < n; first += slice) {
    if (grpc::Status st = BatchCoords(request, index, first, std::min(slice, n - first), &probe);
        !st.ok()) {
      return st;
    }
  }
  return grpc::Status::OK;
}

// A batch is answered a slice of this many chunks at a time: the next slice is evaluated only
// once the last chunk of this one was taken by the transport (the writer blocks under flow
// control), so a batch holds at most a slice's answers ahead of its client, however long it is.
constexpr int kSliceChunks = 4;
// The first chunk holds at most this many results; each one the transport took doubles the next,
// up to the batch's chunk size (issue 40). A client that does not read fills HTTP/2's 64 KiB
// stream window with the first few small chunks, and the batch then waits holding one of ~32
// results (~40 kB on the wire, ~60 kB as a message at 101 bands), not one of 256 (~0.3 MB and
// ~0.5 MB): with 200 such batches open that was ~150 MB of brdfd's memory.
constexpr int kFirstChunkResults = 8;

// The uncertainty a batch's results carry, for their size.
BatchUncertainty UncertaintyOf(const BatchRequest& batch) {
  const v1::InterpolateBatchRequest& request = batch.settings;
  if (!request.include_uncertainty()) return BatchUncertainty::kNone;
  return request.include_uncertainty_shared() ? BatchUncertainty::kPartsAndShared
                                              : BatchUncertainty::kParts;
}

// What a batch holds while it streams, bytes (for the memory budget, rpc/memory_budget.h): its
// request (as parsed: batch_request.h), and per slice the coordinates, the octant method's sort and
// blends (~200 bytes a query) and the chunks of full answers (ResultBytes: ~1.2 kB each with
// provenance at 101 bands, ~3.6 kB at 401; two or three more spectra of floats with the
// uncertainty).
std::uint64_t BatchBytes(const BatchRequest& request, int chunk, std::size_t bands) {
  const auto n = static_cast<std::uint64_t>(request.directions.size());
  const std::uint64_t slice = std::min<std::uint64_t>(n, std::uint64_t{kSliceChunks} * chunk);
  const std::uint64_t answer = ResultBytes(bands, UncertaintyOf(request));
  return request.Bytes() + slice * (200 + answer) + 2ULL * chunk * answer;
}

// A chunk stays under half a client's receive limit whatever the session's grid (the same answer
// in more chunks; clients place results by first_index); then the batch's memory is reserved
// (RESOURCE_EXHAUSTED naming [server] memory_budget_mb when it does not fit).
grpc::Status FitChunkAndReserve(const BatchRequest& request, const IndexSnapshot& index,
                                StreamRegistry::Slot& slot, int* chunk) {
  *chunk = static_cast<int>(MaxChunkResults(static_cast<std::uint32_t>(*chunk), index.grid.count,
                                            UncertaintyOf(request)));
  return slot.Reserve(BatchBytes(request, *chunk, index.grid.count));
}

// A batch's results on their way out: gathered into chunks that grow from kFirstChunkResults to
// the batch's chunk size, each written when full (the write blocks while the client is slow to
// read: HTTP/2 flow control) or at the last result.
class BatchChunks {
 public:
  // `n` results in all, chunks of at most `chunk`.
  BatchChunks(grpc::ServerContext& context, const StopSignal& stopping, StreamRegistry::Slot& slot,
              BatchStreamer& writer, int n, int chunk)
      : context_(context),
        stopping_(stopping),
        slot_(slot),
        writer_(writer),
        n_(n),
        chunk_(chunk),
        size_(std::min(chunk, kFirstChunkResults)) {}

  // Where result `i` goes, or null when the batch must stop (outcome() says why): the client
  // cancelled or the daemon is stopping, looked at as each chunk starts.
  v1::InterpolationResult* Add(int i) {
    if (out_.results_size() == 0) {
      if (context_.IsCancelled()) {
        outcome_ = grpc::Status(grpc::StatusCode::CANCELLED,
                                "InterpolateBatch: cancelled by the client after " +
                                    std::to_string(i) + " of " + std::to_string(n_) + " results");
        return nullptr;
      }
      if (stopping_.stopped()) {
        outcome_ = grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                "InterpolateBatch: the daemon is shutting down after " +
                                    std::to_string(i) + " of " + std::to_string(n_) +
                                    " results; ask again for the rest once it is back");
        return nullptr;
      }
      out_.set_first_index(static_cast<std::uint32_t>(i));
    }
    return out_.add_results();
  }

  // Result `i` is filled in: writes the chunk if it is full or `i` the last. False when the
  // client went away.
  bool Filled(int i) {
    if (out_.results_size() < size_ && i + 1 < n_) return true;
    // The chunk's memory goes back before the wait for a work permit: Clear() would keep every
    // result's spectrum and vertices for reuse, ~0.4 MB for 256 results, while the batch waits
    // its turn (issue 40: 200 waiting batches held ~74 MB so).
    if (!slot_.WriteAndRelease(&writer_, &out_)) {
      outcome_ =
          grpc::Status(grpc::StatusCode::CANCELLED, "InterpolateBatch: the client went away");
      return false;
    }
    size_ = std::min(chunk_, 2 * size_);
    return true;
  }

  // Directions to evaluate at a time: kSliceChunks chunks of the current size.
  int slice() const { return kSliceChunks * size_; }
  const grpc::Status& outcome() const { return outcome_; }

 private:
  grpc::ServerContext& context_;
  const StopSignal& stopping_;
  StreamRegistry::Slot& slot_;
  BatchStreamer& writer_;
  const int n_;
  const int chunk_;
  int size_;  // of the chunk being filled
  v1::InterpolateBatchChunk out_;
  grpc::Status outcome_ = grpc::Status::OK;
};

}  // namespace

grpc::Status InterpolationService::WireBatch(grpc::ServerContext* context,
                                             BatchStreamer* streamer) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  std::unique_ptr<StreamRegistry::Slot> slot;
  if (grpc::Status st =
          streams_.Open(*context, &caller, "InterpolateBatch", &slot, /*computes=*/true);
      !st.ok())
    return st;
  // Read only now, with the work permit: a batch waiting for one holds no request.
  BatchRequest request;
  if (grpc::Status st = ReadBatchRequest(*streamer, &request); !st.ok()) return st;
  SessionId id = 0;
  Settings settings;
  int chunk = 0;
  if (grpc::Status st = CheckBatch(request, &id, &settings, &chunk); !st.ok()) return st;

  // One snapshot for the whole batch: every result sees the same readings.
  Result<std::shared_ptr<const IndexSnapshot>> got =
      cache_.Get(id, settings.quantity, settings.method, settings.options);
  if (!got.ok()) return ToGrpcStatus(got.status());
  const IndexSnapshot& index = **got;
  if (grpc::Status st = CheckOptionsFit(settings.options, index); !st.ok()) return st;
  if (grpc::Status st = FitChunkAndReserve(request, index, *slot, &chunk); !st.ok()) return st;

  // A slice of kSliceChunks chunks (of the size they have then) at a time in one EvaluateEach
  // (the octant method sorts it by cell), its answers streamed chunk by chunk as they come, in
  // order.
  const int n = static_cast<int>(request.directions.size());
  if (grpc::Status st = CheckBatchDirections(request, index, kSliceChunks * chunk); !st.ok()) {
    return st;
  }
  BatchChunks chunks(*context, stopping_, *slot, *streamer, n, chunk);
  // A batch's answers leave `combined` to the client, and `shared` unless asked (brdf.proto).
  const WithUncertainty with_uncertainty =
      request.settings.include_uncertainty()
          ? WithUncertainty(UncertaintyParts{request.settings.include_uncertainty_shared(), false})
          : std::nullopt;
  std::vector<double> coords;
  for (int first = 0, count = 0; first < n && chunks.outcome().ok(); first += count) {
    count = std::min(chunks.slice(), n - first);
    if (grpc::Status st = BatchCoords(request, index, first, count, &coords); !st.ok()) return st;
    bool going = true;
    index.interpolator->EvaluateEach(coords, [&](std::size_t k, interp::Interpolation&& answer) {
      const int i = first + static_cast<int>(k);
      v1::InterpolationResult* result = chunks.Add(i);
      if (result == nullptr) return going = false;
      ToResult(request.directions[static_cast<std::size_t>(i)], std::move(answer), settings, index,
               VertexSpectra::kOmit, with_uncertainty, result);
      return going = chunks.Filled(i);
    });
    if (!going) break;
  }
  return chunks.outcome();
}

}  // namespace brdf::daemon
