#include "daemon/stream_readings.h"

#include <vector>

namespace brdf::daemon {
namespace {

// Readings per page read from the store (and written before the next page is read).
constexpr int kPageSize = 256;

}  // namespace

grpc::Status CheckStreamReadings(grpc::ServerContext& context,
                                 const v1::StreamReadingsRequest& request,
                                 const Authenticator& auth, StreamRegistry& streams,
                                 StreamReadingsCall* call) {
  if (grpc::Status st = auth.Authorize(context, Access::kRead, "StreamReadings", &call->caller);
      !st.ok()) {
    return st;
  }
  if (grpc::Status st = streams.Open(context, &call->caller, "StreamReadings", &call->slot);
      !st.ok()) {
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

grpc::Status StreamSessionReadings(grpc::ServerContext& context,
                                   const v1::StreamReadingsRequest& request,
                                   StreamReadingsCall& call, const ReadingExtras& extras,
                                   const ReadingSource& source,
                                   grpc::ServerWriter<v1::Reading>* writer) {
  std::int64_t last = request.after_id();
  for (;;) {
    if (context.IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "StreamReadings: cancelled by the client");
    }
    bool ended = !request.follow();
    if (!ended) {
      Result<bool> now = source.ended();
      if (!now.ok()) return ToGrpcStatus(now.status());
      ended = *now;
    }
    Result<std::vector<storage::ReadingRecord>> page =
        source.reader->GetReadings(call.session, last, kPageSize);
    if (!page.ok()) return ToGrpcStatus(page.status());
    for (const storage::ReadingRecord& r : *page) {
      last = r.id;
      if (!call.kinds.empty() && call.kinds.count(r.kind) == 0) continue;
      if (!call.slot->Write(writer, ToProtoReading(r, extras))) {
        return grpc::Status(grpc::StatusCode::CANCELLED, "StreamReadings: the client went away");
      }
    }
    if (static_cast<int>(page->size()) == kPageSize) continue;  // more stored: next page now
    if (ended) return grpc::Status::OK;
    if (source.wait()) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          "StreamReadings: " + source.server +
                              " is shutting down; resume with after_id = " + std::to_string(last) +
                              " once it is back");
    }
  }
}

}  // namespace brdf::daemon
