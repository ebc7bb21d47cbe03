#include "daemon/api/stream_readings.h"

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace brdf::daemon {
namespace {

// Readings per page read from the store (and written before the next page is read).
constexpr int kPageSize = 256;
// StreamReadingPoints reads larger pages (fewer queries; its readings carry no spectrum).
constexpr int kPointsPageSize = 8192;
// Readings per StreamReadingPoints message (8 numbers each: well under gRPC's 4 MB).
constexpr int kPointsPerMessage = 8192;

}  // namespace

grpc::Status CheckStreamReadings(grpc::ServerContext& context,
                                 const v1::StreamReadingsRequest& request, const char* rpc,
                                 const Authenticator& auth, StreamRegistry& streams,
                                 StreamReadingsCall* call) {
  call->rpc = rpc;
  if (grpc::Status st = auth.CallerOf(context, &call->caller); !st.ok()) return st;
  if (grpc::Status st = streams.Open(context, &call->caller, rpc, &call->slot); !st.ok()) {
    return st;
  }
  if (grpc::Status st = ParseSessionIdField(request.session_id(), "session_id", &call->session);
      !st.ok()) {
    return st;
  }
  if (grpc::Status st = ParseReadingKinds(request, &call->kinds); !st.ok()) return st;
  if (request.after_id() < 0) {
    return InvalidField("after_id", "must be ≥ 0 (got " + std::to_string(request.after_id()) +
                                        "); 0 starts from the first reading");
  }
  return grpc::Status::OK;
}

ReadingExtras ReadingExtrasOf(storage::SessionReader& reader, std::int64_t session,
                              std::uint32_t averages) {
  ReadingExtras extras;
  if (Result<std::vector<storage::StepRecord>> steps = reader.GetSteps(session); steps.ok()) {
    for (const storage::StepRecord& step : *steps) extras.step_labels[step.step_index] = step.label;
  }
  if (averages > 0) extras.averages = averages;
  return extras;
}

namespace {

// The page loop both streams share: the session's readings in id order a page at a time (read by
// `read_page`: whole readings, or only where they were taken), and with `follow` those that
// arrive later. on_page gets each page's readings of the asked kinds and whether more are stored
// right now (false before the stream waits or ends); it returns false when the client went away.
template <typename Record>
grpc::Status ForEachReadingPage(
    grpc::ServerContext& context, const v1::StreamReadingsRequest& request,
    StreamReadingsCall& call, const ReadingSource& source, int page_size,
    const std::function<Result<std::vector<Record>>(std::int64_t after_id, int limit)>& read_page,
    const std::function<bool(const std::vector<const Record*>&, bool more_stored)>& on_page) {
  std::int64_t last = request.after_id();
  std::vector<const Record*> kept;
  for (;;) {
    if (context.IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED,
                          std::string(call.rpc) + ": cancelled by the client");
    }
    bool ended = !request.follow();
    if (!ended) {
      Result<bool> now = source.ended();
      if (!now.ok()) return ToGrpcStatus(now.status());
      ended = *now;
    }
    Result<std::vector<Record>> page = read_page(last, page_size);
    if (!page.ok()) return ToGrpcStatus(page.status());
    kept.clear();
    for (const Record& r : *page) {
      last = r.id;
      if (call.kinds.empty() || call.kinds.count(r.kind) != 0) kept.push_back(&r);
    }
    const bool more_stored = static_cast<int>(page->size()) == page_size;
    if (!on_page(kept, more_stored)) {
      return grpc::Status(grpc::StatusCode::CANCELLED,
                          std::string(call.rpc) + ": the client went away");
    }
    if (more_stored) continue;  // next page now
    if (ended) return grpc::Status::OK;
    if (source.wait(last)) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          std::string(call.rpc) + ": " + source.server +
                              " is shutting down; resume with after_id = " + std::to_string(last) +
                              " once it is back");
    }
  }
}

}  // namespace

grpc::Status StreamSessionReadings(grpc::ServerContext& context,
                                   const v1::StreamReadingsRequest& request,
                                   StreamReadingsCall& call, const ReadingSource& source,
                                   grpc::ServerWriter<v1::Reading>* writer) {
  const ReadingExtras extras = source.extras();
  // The page after a wait comes from the catalogue's fan-out when it holds it (one store read per
  // commit for all followers); the pages before (catching up) from the store.
  ReadingSource waiting = source;
  bool waited = false;
  waiting.wait = [&](std::int64_t last_id) {
    waited = true;
    return source.wait(last_id);
  };
  return ForEachReadingPage<storage::ReadingRecord>(
      context, request, call, waiting, kPageSize,
      [&](std::int64_t after_id, int limit) -> Result<std::vector<storage::ReadingRecord>> {
        if (std::exchange(waited, false) && source.recent) {
          BRDF_ASSIGN_OR_RETURN(std::optional<std::vector<storage::ReadingRecord>> held,
                                source.recent(after_id, limit));
          if (held.has_value()) return std::move(*held);
        }
        return source.reader->GetReadings(call.session, after_id, limit);
      },
      [&](const std::vector<const storage::ReadingRecord*>& page, bool) {
        for (const storage::ReadingRecord* r : page) {
          if (!call.slot->Write(writer, ToProtoReading(*r, extras))) return false;
        }
        return true;
      });
}

grpc::Status StreamSessionReadingPoints(grpc::ServerContext& context,
                                        const v1::StreamReadingsRequest& request,
                                        StreamReadingsCall& call, const ReadingSource& source,
                                        grpc::ServerWriter<v1::ReadingPoints>* writer) {
  v1::ReadingPoints points;
  return ForEachReadingPage<storage::ReadingPointRecord>(
      context, request, call, source, kPointsPageSize,
      [&](std::int64_t after_id, int limit) {
        return source.reader->GetReadingPoints(call.session, after_id, limit);
      },
      [&](const std::vector<const storage::ReadingPointRecord*>& page, bool more_stored) {
        for (const storage::ReadingPointRecord* r : page) {
          AddReadingPoint(*r, &points);
          if (points.ids_size() == kPointsPerMessage) {
            if (!call.slot->Write(writer, points)) return false;
            points.Clear();
          }
        }
        // Whatever is held goes out before the stream waits for more or ends.
        if (!more_stored && points.ids_size() > 0) {
          if (!call.slot->Write(writer, points)) return false;
          points.Clear();
        }
        return true;
      });
}

}  // namespace brdf::daemon
