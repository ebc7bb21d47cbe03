// The Interpolation service (brdf.proto): spectra at directions that were not measured, from the
// session's index (index_cache.h). Every request is checked before any work: angles finite and
// in range (θ in [0, 90], φ in [−180, 360]), the direction's form set, enums known, options
// positive, batches of 1 … kMaxBatchDirections directions with chunks of at most kMaxChunkSize
// (service_common.h: 100,000 directions; chunks of 256 results by default, at most 1,024).
// Errors name the field and, in a batch, the index: INVALID_ARGUMENT "directions[17].iso.phi:
// must be a finite angle …" (NaN, ±inf, out of range, no direction set, an empty batch, an
// unknown enum, a chunk_size over the limit); NOT_FOUND for an unknown session; RESOURCE_EXHAUSTED
// for more than kMaxBatchDirections directions (or a request over kMaxReceiveMessageBytes, which
// gRPC refuses before it reaches the service).
// Isotropic sessions take `iso` directions (φ folded into [0, 180], exact for an isotropic
// sample) or `four` (reduced to iso); anisotropic sessions take `four` only (φ wrapped into
// (−180, 180], the range of the stored readings).
//
// A batch is answered from ONE snapshot of the index, so all its results see the same readings
// even while the session goes on. Chunks are written with the synchronous writer, which blocks
// while the client is slow to read (gRPC flow control): each chunk is evaluated only once the
// previous one has been taken by the transport, so the server holds about one chunk per stream
// (plus what HTTP/2's flow-control window lets through), never the whole answer. A client that
// cancels stops the batch at the next chunk.
#pragma once

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/auth.h"
#include "daemon/index_cache.h"
#include "daemon/service_common.h"

namespace brdf::daemon {

// Interpolate runs on gRPC's callback API: the answer takes microseconds, so it is computed on
// the thread that read the request and finished there, with no hand-off to a call thread and back
// (each hand-off is a thread wake-up, which on a loaded 2-core machine costs more than the
// answer); this halved brdfd's CPU per call (bench/daemon). The one slow case, the first query
// of a session whose index must be loaded and built, blocks that thread meanwhile (gRPC has
// others). InterpolateBatch stays on the synchronous API: its writer blocks under flow control.
class InterpolationService final
    : public v1::Interpolation::WithCallbackMethod_Interpolate<v1::Interpolation::Service> {
 public:
  // All three must outlive the service.
  InterpolationService(IndexCache& cache, const Authenticator& auth, const StopSignal& stopping);

  grpc::ServerUnaryReactor* Interpolate(grpc::CallbackServerContext* context,
                                        const v1::InterpolateRequest* request,
                                        v1::InterpolateResponse* response) override;
  grpc::Status InterpolateBatch(grpc::ServerContext* context,
                                const v1::InterpolateBatchRequest* request,
                                grpc::ServerWriter<v1::InterpolateBatchChunk>* writer) override;

 private:
  grpc::Status Answer(const grpc::ServerContextBase& context, const v1::InterpolateRequest& request,
                      v1::InterpolateResponse* response);

  IndexCache& cache_;
  const Authenticator& auth_;
  const StopSignal& stopping_;
};

}  // namespace brdf::daemon
