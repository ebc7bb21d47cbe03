// The Interpolation service (brdf.proto): spectra at directions that were not measured, from the
// session's index (index_cache.h). Every request is checked before any work: angles finite and
// in range (θ in [0, 90]; the relative azimuth φ of `iso` in [0, 180]; the azimuths φi, φo of
// `four` in [−360, 360]), the direction's form set, enums known, options positive, batches of 1 …
// kMaxBatchDirections directions with chunks of at most kMaxChunkSize (common.h: 100,000
// directions; chunks of 256 results by default, at most 1,024). Errors name the field and, in a
// batch, the index: INVALID_ARGUMENT "directions[17].iso.phi: must be a finite angle …" (NaN, ±inf,
// out of range, no direction set, an empty batch, an unknown enum, a chunk_size over the limit);
// NOT_FOUND for an unknown session; RESOURCE_EXHAUSTED for more than kMaxBatchDirections directions
// (or a request over kMaxReceiveMessageBytes, which gRPC refuses before it reaches the service).
// Isotropic sessions take `iso` directions or `four` (reduced to iso); anisotropic sessions take
// `four` only (φi, φo taken modulo 360 into (−180, 180], the range of the stored readings).
// Once the index is at hand, the options must fit it (CheckOptionsFit: axis_scale of the
// session's dimension).
// Interpolate with include_vertex_spectra also gives each vertex its sample's own spectrum, from
// the snapshot the answer came from, in the answer's quantity (the paper's Figure 8 in one call).
//
// A batch is answered from ONE snapshot of the index, so all its results see the same readings
// even while the session goes on. Chunks are written with the synchronous writer, which blocks
// while the client is slow to read (gRPC flow control): each chunk is evaluated only once the
// previous one has been taken by the transport, so the server holds about one chunk per stream
// (plus what HTTP/2's flow-control window lets through), never the whole answer. The first chunk
// holds 8 results and each one taken doubles the next up to the chunk size (issue 40): a client
// that does not read leaves one chunk of ~32 results waiting in brdfd, not one of 256. A client
// that cancels stops the batch at the next chunk.
//
// RenderAppearance (service_appearance.cc) renders the sample's colour and a lit sphere under
// CIE illuminants (core/appearance.h) from the session's BRDF index in this cache, behind the
// exports' fill chain: the chosen method, then Delaunay (the cache's index, built only when a
// pixel needs it), then the Cook-Torrance model fitted to the index's samples (only when a pixel
// needs it). Isotropic sessions only: an anisotropic one is FAILED_PRECONDITION. Checked like a
// batch: sphere_size at most kMaxAppearanceSphere (INVALID_ARGUMENT naming it), light 0 or 3
// finite values not all 0, illuminants known and each at most once. It holds a work permit of the
// stream registry while it computes (as InterpolateBatch and Export do).
// Its answers are cached: the last kAppearanceCacheEntries of them, keyed by the index snapshot
// they were rendered from and the request's bytes (deterministic serialization), so the same
// request on a session that has not grown since is answered with the same bytes without
// rendering, and a reading that lands makes the next one render anew. A request identical to one
// being rendered waits for that answer instead of rendering it too (it renders itself only if the
// first was cancelled or its answer depended on the first's deadline). Only cache misses take a
// work permit.
#pragma once

#include <atomic>
#include <cstdint>
#include <list>
#include <memory>
#include <optional>
#include <string>

#include "brdf/v1/brdf.grpc.pb.h"
#include "core/mutex.h"
#include "daemon/api/batch_request.h"
#include "daemon/api/common.h"
#include "daemon/index/cache.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/stream_registry.h"

namespace brdf::daemon {

// RenderAppearance's default and largest sphere, pixels per side (512² RGBA is 1 MiB per
// illuminant, under a client's default 4 MiB receive limit for both).
inline constexpr std::uint32_t kDefaultAppearanceSphere = 128;
inline constexpr std::uint32_t kMaxAppearanceSphere = 512;
// RenderAppearance's answers kept (at most 2 MiB each: two spheres of kMaxAppearanceSphere²).
inline constexpr std::size_t kAppearanceCacheEntries = 8;

// InterpolationOptions checked (INVALID_ARGUMENT naming options.axis_scale[i] or
// options.coordinates) into the interpolator's options.
grpc::Status ParseInterpolationOptions(const v1::InterpolationOptions& options,
                                       interp::Options* out);

// The options fit the session of `index`: axis_scale none or one value per axis of the index (3
// isotropic, 4 anisotropic), symmetries and coordinates its kind allows (daemon/index/build.h:
// CheckIndexOptions). Checked on every answer, a cache hit included: INVALID_ARGUMENT naming the
// option.
grpc::Status CheckOptionsFit(const interp::Options& options, const IndexSnapshot& index);

// Interpolate is served on gRPC's completion-queue API by InterpolateLoop (interpolate_loop.h),
// from threads of brdfd's own: the answer takes microseconds, so a loop thread computes it where
// it took the request (AnswerIfReady) and only a query that must first load or extend the index
// goes to a thread that may block (Answer). InterpolateBatch stays on the synchronous API (its
// writer blocks under flow control), reading its own request once it has a work permit
// (batch_request.h).
class InterpolationService final
    : public WithWireBatchRequest<
          v1::Interpolation::WithAsyncMethod_Interpolate<v1::Interpolation::Service>> {
 public:
  // All three must outlive the service.
  InterpolationService(IndexCache& cache, const Authenticator& auth, const StopSignal& stopping,
                       StreamRegistry& streams);

  grpc::Status WireBatch(grpc::ServerContext* context, BatchStreamer* streamer) override;
  grpc::Status RenderAppearance(grpc::ServerContext* context, const v1::AppearanceRequest* request,
                                v1::AppearanceResponse* response) override;

  // Interpolate's answer (or its error) when the cache holds a current index for the request
  // (IndexCache::FreshHit): never reads the store nor builds. nullopt when the index must first be
  // loaded, extended or built; then call Answer, which may take as long as that.
  // The call was admitted at its door (rpc/token_gate.h): neither needs its context.
  std::optional<grpc::Status> AnswerIfReady(const v1::InterpolateRequest& request,
                                            v1::InterpolateResponse* response);
  // Interpolate's answer, loading or extending the index first if need be.
  grpc::Status Answer(const v1::InterpolateRequest& request, v1::InterpolateResponse* response);

  // RenderAppearance's renders since the start (cache misses that rendered), and its answers
  // served from the cache or from an identical request's render.
  std::uint64_t appearance_renders() const { return appearance_renders_.load(); }
  std::uint64_t appearance_reuses() const { return appearance_reuses_.load(); }
  // RenderAppearance's renders under way (each with the identical calls that wait for it).
  std::size_t appearance_flights() const;

 private:
  // What a RenderAppearance answer depends on: the index snapshot (its address, alive while
  // `index` is: a later snapshot at a freed one's address never matches) and the request.
  struct AppearanceKey {
    const IndexSnapshot* index = nullptr;
    SessionId session = 0;
    std::int64_t through_reading_id = 0;
    std::string request;  // AppearanceRequest, serialized deterministically
    bool operator==(const AppearanceKey&) const = default;
  };
  struct AppearanceEntry {
    AppearanceKey key;
    std::weak_ptr<const IndexSnapshot> index;
    std::shared_ptr<const v1::AppearanceResponse> response;
  };
  // A render under way; its waiters read the outcome once `done`.
  struct AppearanceFlight {
    AppearanceKey key;
    bool done = false;
    // The outcome holds for any caller (false: cancelled, or a stage of the fill chain failed for
    // a reason of this call, its deadline): a waiter then renders itself.
    bool shared = false;
    grpc::Status status;
    std::shared_ptr<const v1::AppearanceResponse> response;
  };
  // The cached answer for `key` (moved to the front), or null; drops entries whose snapshot is
  // gone.
  std::shared_ptr<const v1::AppearanceResponse> CachedAppearance(const AppearanceKey& key)
      REQUIRES(appearance_mu_);
  // RenderAppearance's answer when the cache holds it or an identical call renders it (waiting
  // for that call), or the call's end (cancelled, stopping); nullopt with `*flight` registered
  // when this call must render.
  std::optional<grpc::Status> AwaitAppearance(grpc::ServerContext& context,
                                              const AppearanceKey& key,
                                              v1::AppearanceResponse* response,
                                              std::shared_ptr<AppearanceFlight>* flight);
  // A render's outcome handed to the calls waiting on `flight`, and cached when it holds for any
  // call (`lasting`, not cancelled).
  void LandAppearance(const std::shared_ptr<AppearanceFlight>& flight,
                      const std::shared_ptr<const IndexSnapshot>& index,
                      const std::shared_ptr<v1::AppearanceResponse>& rendered,
                      const grpc::Status& st, bool lasting);

  // Both of the above; with `may_load` false, returns nullopt where it would load.
  std::optional<grpc::Status> Respond(const v1::InterpolateRequest& request,
                                      v1::InterpolateResponse* response, bool may_load);

  IndexCache& cache_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
  StreamRegistry& streams_;

  mutable Mutex appearance_mu_;
  CondVar appearance_done_;                                                 // a flight ended
  std::list<AppearanceEntry> appearance_cache_ GUARDED_BY(appearance_mu_);  // most recent first
  std::list<std::shared_ptr<AppearanceFlight>> appearance_flights_ GUARDED_BY(appearance_mu_);
  std::atomic<std::uint64_t> appearance_renders_{0};
  std::atomic<std::uint64_t> appearance_reuses_{0};
};

}  // namespace brdf::daemon
