// StreamReadings' (and StreamReadingPoints') work for the Data service (data.h, over any
// SessionCatalogue's reader: the rig's store, the archive): the request checked, then the
// session's readings written in id order a page at a time (memory bounded by one page), and with
// `follow` the readings that arrive later, until the session ends, the client cancels or the
// server stops. StreamReadings runs on the stream pump (gRPC's callback API: a following stream
// that waits holds no thread); StreamReadingPoints, a one-off for the browser's figure, on
// gRPC's synchronous pool. Both share one page loop (ReadingPager in the .cc).
#pragma once

#include <functional>
#include <memory>
#include <set>
#include <string>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/common.h"
#include "daemon/api/pumped_stream.h"
#include "daemon/api/session_catalogue.h"
#include "daemon/rpc/auth.h"
#include "daemon/rpc/stream_registry.h"
#include "daemon/wire/reading.h"
#include "storage/session_reader.h"

namespace brdf::daemon {

// A checked StreamReadings request: the caller authorized (kRead), a stream slot taken, the
// session id, kinds and after_id valid (else the status names the field). `rpc` is the method
// the client called ("StreamReadings" or "StreamReadingPoints", which take the same request):
// the stream's errors and the authorization and stream-limit messages name it.
struct StreamReadingsCall {
  const char* rpc = "StreamReadings";
  Caller caller;
  std::unique_ptr<StreamRegistry::Slot> slot;
  std::int64_t session = 0;
  std::set<storage::ReadingKind> kinds;  // empty: every kind
};
grpc::Status CheckStreamReadings(grpc::ServerContextBase& context,
                                 const v1::StreamReadingsRequest& request, const char* rpc,
                                 const Authenticator& auth, StreamRegistry& streams,
                                 StreamReadingsCall* call);

// Where the readings come from, and how the stream learns that more may come.
struct ReadingSource {
  storage::SessionReader* reader = nullptr;
  // With follow, asked BEFORE each page: true when the session will get no reading after what
  // the next page reads (so a short page then ends the stream).
  std::function<Result<bool>()> ended;
  // With follow, after a short page of a session not ended (its last reading id given): waits
  // until more may be there, or a while; true when the server is stopping (the stream then ends
  // with UNAVAILABLE).
  std::function<bool(std::int64_t last_id)> wait;
  // With follow, the page after a wait, when the catalogue holds it for all its followers
  // (SessionFollow::recent; nullopt or empty: read `reader`).
  std::function<Result<std::optional<std::vector<storage::ReadingRecord>>>(std::int64_t after_id,
                                                                           int limit)>
      recent;
  std::string server = "the server";  // in the stopping message ("brdfd is shutting down; …")
  // The session's step labels and averaging (ReadingExtrasOf), for the readings that carry them:
  // StreamReadings asks once, before its first page; StreamReadingPoints never (a session of
  // 50,000 steps is 50,000 labels read for nothing). Shared by the streams of the session
  // (shared_extras.h).
  std::function<std::shared_ptr<const ReadingExtras>()> extras;
  // For StreamReadings (served without a thread of its own), instead of `wait`: the catalogue's
  // SessionFollow::notify (empty: the stream looks again every second).
  std::function<void(std::int64_t last_id, std::function<void()> wake)> notify;
};

// A readings stream once opened: the checked call, the catalogue's follow of the session and the
// source over them (whose functions refer to `follow`: the struct stays where it was made).
struct OpenedReadings {
  StreamReadingsCall call;
  SessionFollow follow;
  ReadingSource source;
};
// Opens a readings stream (the Data service's: the request checked, the session looked up, the
// source set up): OK with *opened filled, or the status the stream ends with.
using OpenReadings = std::function<grpc::Status(OpenedReadings* opened)>;

// What a readings stream does once its request is checked and its source set up (the Data
// service shares its set-up between StreamReadings and StreamReadingPoints).
using ReadingStreamBody =
    std::function<grpc::Status(StreamReadingsCall& call, const ReadingSource& source)>;

// The session's step labels from `reader`, with the plan's averaging count (0: 1).
ReadingExtras ReadingExtrasOf(storage::SessionReader& reader, std::int64_t session,
                              std::uint32_t averages);

// StreamReadings as a PumpedStream's body (pumped_stream.h: on gRPC's callback API, no thread
// held while it waits): opened with `open` at its first step (on the pump, not gRPC's thread),
// then the session's readings one message a step, a page read from the store at a time, and with
// `follow` the readings that arrive later (woken by the catalogue's notify), until the session
// ends, the client cancels or `stopping` (then UNAVAILABLE naming the after_id to resume from).
std::unique_ptr<StreamBody<v1::Reading>> StreamReadingsBody(
    grpc::CallbackServerContext& context, const v1::StreamReadingsRequest& request,
    const StopSignal& stopping, OpenReadings open);

// The same readings as columns (StreamReadingPoints): up to 8,192 a message, and what is held is
// written before the stream waits (follow) or ends.
grpc::Status StreamSessionReadingPoints(grpc::ServerContext& context,
                                        const v1::StreamReadingsRequest& request,
                                        StreamReadingsCall& call, const ReadingSource& source,
                                        grpc::ServerWriter<v1::ReadingPoints>* writer);

}  // namespace brdf::daemon
