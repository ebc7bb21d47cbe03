// What the three gRPC services share: the limits every request is checked against, the mapping
// of brdfd's Status codes onto gRPC codes (engine/session_manager.h's table), argument checks that
// name the offending field (the values themselves are read by wire/enums.h), and the server-wide
// "stopping" signal that ends long-lived streams at shutdown.
#pragma once

#include <grpcpp/support/status.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <set>
#include <string>

#include "brdf/v1/brdf.pb.h"
#include "core/client_text.h"
#include "core/interp/interpolator.h"
#include "core/mutex.h"
#include "core/readings/quantity.h"
#include "core/status.h"
#include "daemon/rpc/auth.h"
#include "storage/records.h"

namespace brdf::daemon {

// Largest request the server accepts (a plan at core/plan's step cap is ~8 MB of JSON; a batch of
// kMaxBatchDirections iso directions is ~3 MB). Larger ones fail with RESOURCE_EXHAUSTED.
inline constexpr int kMaxReceiveMessageBytes = 16 * 1024 * 1024;
// Directions per InterpolateBatch request.
inline constexpr int kMaxBatchDirections = 100000;
// Results per InterpolateBatch chunk: default, and the most a client may ask (1,024 results of
// 101 bands with provenance are ~1.2 MB, well under a client's default 4 MiB receive limit; of
// 401 bands ~3.6 MB, near it: see MaxChunkResults).
inline constexpr std::uint32_t kDefaultChunkSize = 256;
inline constexpr std::uint32_t kMaxChunkSize = 1024;
// With include_uncertainty a result carries two or three more spectra (of floats; ~2.5 kB a
// result at 101 bands): at most 512 (~1.3 MB) per chunk.
inline constexpr std::uint32_t kMaxUncertainChunkSize = 512;
// A client's default receive limit (gRPC's 4 MiB), which an InterpolateBatch chunk must stay under.
inline constexpr std::uint64_t kClientReceiveLimitBytes = 4 * 1024 * 1024;
// The uncertainty an InterpolateBatch result carries (InterpolateBatchRequest.include_uncertainty
// and include_uncertainty_shared): none; the measurement and interpolation parts; and the shared
// part too. Never `combined`: clients compute it (brdf.proto, InterpolationUncertainty).
enum class BatchUncertainty { kNone, kParts, kPartsAndShared };
// Wire bytes of one InterpolateBatch result of `bands` bands, bounded above: 8 per band (packed
// double), the result's fixed part (status, directions, grid, up to 5 vertices with ids, weights
// and detail) within kResultOverheadBytes. 101 bands: 1,208 (the 1,200 B the batch budget took).
// With its uncertainty: 4 per band (packed float) for each part it carries, and the not-estimated
// texts (a vertex without a budget, the budgets' terms not estimated: a few lines of ~100 B).
inline constexpr std::uint64_t kResultOverheadBytes = 400;
inline constexpr std::uint64_t kUncertaintyTextBytes = 512;
inline constexpr std::uint64_t ResultBytes(std::size_t bands,
                                           BatchUncertainty uncertainty = BatchUncertainty::kNone) {
  const auto n = static_cast<std::uint64_t>(bands);
  const std::uint64_t parts = uncertainty == BatchUncertainty::kNone    ? 0
                              : uncertainty == BatchUncertainty::kParts ? 2
                                                                        : 3;
  return kResultOverheadBytes + 8 * n + (parts == 0 ? 0 : parts * 4 * n + kUncertaintyTextBytes);
}
// Wire bytes of a chunk of `results` results of `bands` bands.
inline constexpr std::uint64_t ChunkBytes(std::uint64_t results, std::size_t bands,
                                          BatchUncertainty uncertainty = BatchUncertainty::kNone) {
  return results * ResultBytes(bands, uncertainty);
}
// The most results a chunk of `bands` bands may hold: the client's request (0: the default),
// capped at kMaxChunkSize and so that the chunk stays under half a client's default receive
// limit (401 bands: 1,024 → 581; with the uncertainty's two parts 401 bands: 512 → 286, with the
// shared part too 234). The batch's answer is the same, in more chunks.
inline constexpr std::uint32_t MaxChunkResults(
    std::uint32_t requested, std::size_t bands,
    BatchUncertainty uncertainty = BatchUncertainty::kNone) {
  const std::uint64_t fit = kClientReceiveLimitBytes / 2 / ResultBytes(bands, uncertainty);
  const std::uint64_t asked = requested == 0 ? kDefaultChunkSize : requested;
  const std::uint64_t capped = asked < kMaxChunkSize ? asked : kMaxChunkSize;
  return static_cast<std::uint32_t>(capped < fit ? capped : (fit == 0 ? 1 : fit));
}
static_assert(MaxChunkResults(kMaxChunkSize, 101) == kMaxChunkSize);
static_assert(ChunkBytes(kMaxChunkSize, 401) < kClientReceiveLimitBytes);
static_assert(MaxChunkResults(kMaxUncertainChunkSize, 101, BatchUncertainty::kPartsAndShared) ==
              kMaxUncertainChunkSize);
static_assert(MaxChunkResults(kMaxUncertainChunkSize, 401, BatchUncertainty::kParts) == 286);
// Free texts (abort reason, prompt note) are stored in the audit log; longer ones are refused.
inline constexpr std::size_t kMaxNoteBytes = 4096;
// A session id is a positive decimal number of at most 18 digits; ids and page tokens longer than
// this are refused without being echoed back (an error message must stay small: gRPC carries it
// in a trailer, which clients cap at a few KiB).
inline constexpr std::size_t kMaxSessionIdBytes = 32;
// ListSessions: default and largest page.
inline constexpr std::uint32_t kDefaultPageSize = 100;
inline constexpr std::uint32_t kMaxPageSize = 1000;
// How often a long-lived stream (WatchSession, StreamReadings with follow) looks whether its
// client went away or the daemon is stopping.
inline constexpr std::chrono::milliseconds kStreamPollInterval{200};
// How long a stream on the stream pump (pumped_stream.h: WatchSession, StreamReadings) that
// nothing woke waits before it looks again at its client, its session and the server's stop, as
// the synchronous streams' waits did (1 s: an event or a commit wakes it at once).
inline constexpr std::chrono::milliseconds kStreamIdleWait{1000};

// brdfd Status → gRPC status (message through BoundedMessage), code per session_manager.h:
// kInvalidArgument → INVALID_ARGUMENT,
// kNotFound → NOT_FOUND, kFailedPrecondition → FAILED_PRECONDITION, kIoError → UNAVAILABLE,
// kTimeout → DEADLINE_EXCEEDED, kCancelled → CANCELLED, device errors → UNAVAILABLE, kInternal
// and kConfigurationError → INTERNAL. The message is kept, up to kMaxErrorMessageBytes.
grpc::Status ToGrpcStatus(const Status& status);

// A client's string as an error message may quote it: PrintablePrefix (core/client_text.h).
// gRPC carries an error message in a trailer, which clients cap at a few KiB.
using brdf::PrintablePrefix;

// Longest error message brdfd sends (BoundedMessage); the trailer that carries it stays small.
inline constexpr std::size_t kMaxErrorMessageBytes = 1024;
// `message` cut to kMaxErrorMessageBytes at a character boundary, marked with its full length:
// the last guard in case a message quotes more of a client's string than it should.
std::string BoundedMessage(std::string message);

// INVALID_ARGUMENT "<field>: <what>".
grpc::Status InvalidField(const std::string& field, const std::string& what);

// A session id field ("session_id", "page_token") as a number: INVALID_ARGUMENT naming `field`
// when it is empty, too long (kMaxSessionIdBytes: the value is not echoed) or not a positive
// number. Never NOT_FOUND: whether the session exists is the caller's next question.
grpc::Status ParseSessionIdField(const std::string& text, const std::string& field,
                                 std::int64_t* id);

// The API's quantity (UNSPECIFIED: BRDF) and interpolation method (UNSPECIFIED: octant) as
// brdfd's; INVALID_ARGUMENT naming "quantity" / "method" for a value the API does not have.
grpc::Status ParseQuantityField(int quantity, Quantity* out);
grpc::Status ParseMethodField(int method, interp::Method* out);
// InterpolationOptions.coordinates (UNSPECIFIED: incidence) as brdfd's; INVALID_ARGUMENT naming
// "options.coordinates" for a value the API does not have. Whether the session can take half/
// difference coordinates is the index's check (index_build.h: CheckIndexOptions).
grpc::Status ParseCoordinatesField(int coordinates, interp::Coordinates* out);
// InterpolationOptions.trend: unset is NONE; an unknown value names options.trend.
grpc::Status ParseTrendField(int trend, interp::Trend* out);

// Checks a finite angle within [lo, hi]; the message names `field` and the range.
Status CheckAngle(double value, double lo, double hi, const std::string& field);

// A number as an error message shows it: the shortest of iostream's default form ("180.5",
// "1e+300", "inf").
std::string ShortNumber(double v);

// StreamReadingsRequest.kinds as a set (empty: every kind); INVALID_ARGUMENT naming "kinds[i]"
// for a kind the API does not have.
grpc::Status ParseReadingKinds(const v1::StreamReadingsRequest& request,
                               std::set<storage::ReadingKind>* kinds);

// Set once at shutdown; streams end when they see it. Waiters wake at once.
class StopSignal {
 public:
  void Stop();
  bool stopped() const { return stopped_.load(); }
  // Waits up to `d` or until Stop(); true when stopped.
  bool WaitFor(std::chrono::steady_clock::duration d) const;

 private:
  std::atomic<bool> stopped_{false};
  mutable Mutex mu_;
  mutable CondVar cv_;
};

}  // namespace brdf::daemon
