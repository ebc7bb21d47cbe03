#include "daemon/api/stream_readings.h"

#include <atomic>
#include <functional>
#include <memory>
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

grpc::Status CheckStreamReadings(grpc::ServerContextBase& context,
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

// The page loop both streams share, a step at a time: the session's readings in id order a page
// at a time (read by `read_page`: whole readings, or only where they were taken; `after_wait`
// when the stream waited before it), and with `follow` those that arrive later. Next gives a
// page (kept(): its readings of the asked kinds; more_stored: more are stored right now, false
// before the stream waits or ends), kWait (the stream waits for more, then asks Next again) or
// kFinish with the stream's status.
template <typename Record>
class ReadingPager {
 public:
  using ReadPage =
      std::function<Result<std::vector<Record>>(std::int64_t after_id, int limit, bool after_wait)>;
  enum class Kind { kPage, kWait, kFinish };
  struct Step {
    Kind kind;
    grpc::Status status;
    bool more_stored = false;
  };

  ReadingPager(grpc::ServerContextBase& context, const v1::StreamReadingsRequest& request,
               const StreamReadingsCall& call, const ReadingSource& source, int page_size,
               ReadPage read_page)
      : context_(context),
        request_(request),
        call_(call),
        source_(source),
        page_size_(page_size),
        read_page_(std::move(read_page)),
        last_(request.after_id()) {}

  Step Next() {
    if (std::exchange(paged_, false) && !more_stored_) {
      if (ended_) return {Kind::kFinish, grpc::Status::OK};
      waited_ = true;
      return {Kind::kWait, grpc::Status::OK};
    }
    if (context_.IsCancelled()) {
      return Finish(grpc::StatusCode::CANCELLED, ": cancelled by the client");
    }
    ended_ = !request_.follow();
    if (!ended_) {
      Result<bool> now = source_.ended();
      if (!now.ok()) return {Kind::kFinish, ToGrpcStatus(now.status())};
      ended_ = *now;
    }
    Result<std::vector<Record>> page = read_page_(last_, page_size_, std::exchange(waited_, false));
    if (!page.ok()) return {Kind::kFinish, ToGrpcStatus(page.status())};
    page_ = std::move(*page);
    kept_.clear();
    for (const Record& r : page_) {
      last_ = r.id;
      if (call_.kinds.empty() || call_.kinds.count(r.kind) != 0) kept_.push_back(&r);
    }
    more_stored_ = static_cast<int>(page_.size()) == page_size_;
    paged_ = true;
    return {Kind::kPage, grpc::Status::OK, more_stored_};
  }

  const std::vector<const Record*>& kept() const { return kept_; }
  std::int64_t last() const { return last_; }
  // The stream's end when the client went away, or the server is stopping.
  grpc::Status Gone() const {
    return Finish(grpc::StatusCode::CANCELLED, ": the client went away").status;
  }
  grpc::Status Stopping() const {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        std::string(call_.rpc) + ": " + source_.server +
                            " is shutting down; resume with after_id = " + std::to_string(last_) +
                            " once it is back");
  }

 private:
  Step Finish(grpc::StatusCode code, const char* what) const {
    return {Kind::kFinish, grpc::Status(code, std::string(call_.rpc) + what)};
  }

  grpc::ServerContextBase& context_;
  const v1::StreamReadingsRequest& request_;
  const StreamReadingsCall& call_;
  const ReadingSource& source_;
  const int page_size_;
  const ReadPage read_page_;
  std::int64_t last_;
  std::vector<Record> page_;
  std::vector<const Record*> kept_;
  bool paged_ = false;        // a page was given: what follows it is decided at the next call
  bool more_stored_ = false;  // that page was full
  bool ended_ = false;        // the session gets no reading after that page
  bool waited_ = false;       // the next page comes after a wait
};

// The page loop on a thread of its own: waits with source.wait.
template <typename Record>
grpc::Status ForEachReadingPage(
    grpc::ServerContext& context, const v1::StreamReadingsRequest& request,
    StreamReadingsCall& call, const ReadingSource& source, int page_size,
    typename ReadingPager<Record>::ReadPage read_page,
    const std::function<bool(const std::vector<const Record*>&, bool more_stored)>& on_page) {
  using Kind = typename ReadingPager<Record>::Kind;
  ReadingPager<Record> pager(context, request, call, source, page_size, std::move(read_page));
  for (;;) {
    typename ReadingPager<Record>::Step step = pager.Next();
    switch (step.kind) {
      case Kind::kFinish:
        return step.status;
      case Kind::kWait:
        if (source.wait(pager.last())) return pager.Stopping();
        break;
      case Kind::kPage:
        if (!on_page(pager.kept(), step.more_stored)) return pager.Gone();
        break;
    }
  }
}

// StreamReadings on the pump: opened at its first step, then one reading a step.
class ReadingsBody final : public StreamBody<v1::Reading> {
 public:
  ReadingsBody(grpc::CallbackServerContext& context, const v1::StreamReadingsRequest& request,
               const StopSignal& stopping, OpenReadings open)
      : context_(context), request_(request), stopping_(stopping), open_(std::move(open)) {}

  Next Step(const std::function<void()>& wake, v1::Reading* message,
            grpc::Status* status) override {
    if (pager_ == nullptr) {
      if (grpc::Status st = Open(); !st.ok()) return Finished(std::move(st), status);
    }
    if (std::exchange(waiting_, false) && stopping_.stopped()) {
      return Finished(pager_->Stopping(), status);
    }
    for (;;) {
      if (next_ < pager_->kept().size()) {
        *message = ToProtoReading(*pager_->kept()[next_++], *extras_);
        return Next::kWrite;
      }
      ReadingPager<storage::ReadingRecord>::Step step = pager_->Next();
      if (step.kind == ReadingPager<storage::ReadingRecord>::Kind::kFinish) {
        return Finished(std::move(step.status), status);
      }
      if (step.kind == ReadingPager<storage::ReadingRecord>::Kind::kWait) {
        if (stopping_.stopped()) return Finished(pager_->Stopping(), status);
        waiting_ = true;
        Notify(wake);
        return Next::kWait;
      }
      next_ = 0;  // a new page
    }
  }
  grpc::Status WriteFailed() override { return pager_->Gone(); }
  StreamRegistry::Slot* slot() override {
    return opened_ != nullptr ? opened_->call.slot.get() : nullptr;
  }

 private:
  static Next Finished(grpc::Status st, grpc::Status* status) {
    *status = std::move(st);
    return Next::kFinish;
  }
  // Asks the catalogue to wake the stream at the next commit, once: a stream the idle wait woke
  // with nothing new is still registered (an idle follower is one entry, not one a second).
  void Notify(const std::function<void()>& wake) {
    if (!opened_->source.notify || notify_armed_->exchange(true)) return;
    opened_->source.notify(pager_->last(), [armed = notify_armed_, wake] {
      armed->store(false);
      wake();
    });
  }
  grpc::Status Open() {
    opened_ = std::make_unique<OpenedReadings>();
    if (grpc::Status st = open_(opened_.get()); !st.ok()) return st;
    const ReadingSource& source = opened_->source;
    extras_ = source.extras();
    // The page after a wait comes from the catalogue's fan-out when it holds it (one store read
    // per commit for all followers); the pages before (catching up) from the store.
    pager_ = std::make_unique<ReadingPager<storage::ReadingRecord>>(
        context_, request_, opened_->call, source, kPageSize,
        [this](std::int64_t after_id, int limit,
               bool after_wait) -> Result<std::vector<storage::ReadingRecord>> {
          const ReadingSource& from = opened_->source;
          if (after_wait && from.recent) {
            BRDF_ASSIGN_OR_RETURN(std::optional<std::vector<storage::ReadingRecord>> held,
                                  from.recent(after_id, limit));
            if (held.has_value()) return std::move(*held);
          }
          return from.reader->GetReadings(opened_->call.session, after_id, limit);
        });
    return grpc::Status::OK;
  }

  grpc::CallbackServerContext& context_;
  const v1::StreamReadingsRequest& request_;
  const StopSignal& stopping_;
  const OpenReadings open_;
  std::unique_ptr<OpenedReadings> opened_;
  std::shared_ptr<const ReadingExtras> extras_;
  std::unique_ptr<ReadingPager<storage::ReadingRecord>> pager_;
  std::size_t next_ = 0;  // the next of the page's kept readings to write (all written: wait)
  bool waiting_ = false;  // the last step waited for more
  // The catalogue holds a waker of this stream (until the next commit).
  std::shared_ptr<std::atomic<bool>> notify_armed_ = std::make_shared<std::atomic<bool>>(false);
};

}  // namespace

std::unique_ptr<StreamBody<v1::Reading>> StreamReadingsBody(
    grpc::CallbackServerContext& context, const v1::StreamReadingsRequest& request,
    const StopSignal& stopping, OpenReadings open) {
  return std::make_unique<ReadingsBody>(context, request, stopping, std::move(open));
}

grpc::Status StreamSessionReadingPoints(grpc::ServerContext& context,
                                        const v1::StreamReadingsRequest& request,
                                        StreamReadingsCall& call, const ReadingSource& source,
                                        grpc::ServerWriter<v1::ReadingPoints>* writer) {
  v1::ReadingPoints points;
  return ForEachReadingPage<storage::ReadingPointRecord>(
      context, request, call, source, kPointsPageSize,
      [&](std::int64_t after_id, int limit, bool /*after_wait*/) {
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
