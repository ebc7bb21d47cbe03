// Control.WatchSession on the stream pump (pumped_stream.h): a watch that waits for its session's
// next event holds no thread; the event bus wakes it (SessionWatch::OnEvent).
#include <spdlog/spdlog.h>

#include <functional>
#include <memory>
#include <optional>
#include <utility>

#include "daemon/api/control.h"
#include "daemon/api/pumped_stream.h"

namespace brdf::daemon {
namespace {

// A watch once opened: its stream slot and its subscription.
struct OpenedWatch {
  std::unique_ptr<StreamRegistry::Slot> slot;
  std::unique_ptr<SessionWatch> watch;
};
using OpenWatch = std::function<grpc::Status(OpenedWatch* opened)>;

// Opened at its first step (on the pump, not gRPC's thread), then one event a step: the snapshot,
// then every event until the session ends, the client cancels or the server stops.
class WatchBody final : public StreamBody<v1::SessionEvent> {
 public:
  WatchBody(grpc::CallbackServerContext& context, const StopSignal& stopping, OpenWatch open)
      : context_(context), stopping_(stopping), open_(std::move(open)) {}
  ~WatchBody() override {
    if (opened_.watch != nullptr) opened_.watch->Close();
  }

  Next Step(const std::function<void()>& wake, v1::SessionEvent* message,
            grpc::Status* status) override {
    if (!open_tried_) {
      open_tried_ = true;
      if (grpc::Status st = open_(&opened_); !st.ok()) return Finished(std::move(st), status);
      opened_.watch->OnEvent(wake);
    }
    SessionWatch& watch = *opened_.watch;
    if (context_.IsCancelled()) {
      return Finished(
          grpc::Status(grpc::StatusCode::CANCELLED, "WatchSession: cancelled by the client"),
          status);
    }
    // At shutdown, send what is queued (the pause the shutdown made, typically), then end.
    const bool stopping = stopping_.stopped();
    if (std::optional<v1::SessionEvent> event = watch.Next(std::chrono::milliseconds(0))) {
      *message = std::move(*event);
      return Next::kWrite;
    }
    if (watch.ended()) return Finished(grpc::Status::OK, status);
    if (stopping) {
      return Finished(grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                   "WatchSession: the daemon is shutting down; watch again once "
                                   "it is back (the session is kept)"),
                      status);
    }
    return Next::kWait;
  }
  grpc::Status WriteFailed() override {
    return grpc::Status(grpc::StatusCode::CANCELLED, "WatchSession: the client went away");
  }
  StreamRegistry::Slot* slot() override { return opened_.slot.get(); }

 private:
  static Next Finished(grpc::Status st, grpc::Status* status) {
    *status = std::move(st);
    return Next::kFinish;
  }

  grpc::CallbackServerContext& context_;
  const StopSignal& stopping_;
  const OpenWatch open_;
  OpenedWatch opened_;
  bool open_tried_ = false;
};

}  // namespace

grpc::ServerWriteReactor<v1::SessionEvent>* ControlService::WatchSession(
    grpc::CallbackServerContext* context, const v1::WatchSessionRequest* request) {
  OpenWatch open = [this, context, request](OpenedWatch* opened) -> grpc::Status {
    if (rig_ == nullptr) return NoRig("WatchSession", request->session_id());
    Caller caller;
    if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
    if (grpc::Status st = streams_.Open(*context, &caller, "WatchSession", &opened->slot);
        !st.ok()) {
      return st;
    }
    SessionId id = 0;
    if (grpc::Status st = ParseSessionIdField(request->session_id(), "session_id", &id); !st.ok()) {
      return st;
    }
    Result<std::unique_ptr<SessionWatch>> watching = rig_->Watch(id);
    if (!watching.ok()) return ToGrpcStatus(watching.status());
    opened->watch = std::move(*watching);
    spdlog::debug("WatchSession: {} watches session {}", caller.name, id);
    return grpc::Status::OK;
  };
  return new PumpedStream<v1::SessionEvent>(
      pump_, std::make_unique<WatchBody>(*context, stopping_, std::move(open)), kStreamIdleWait);
}

}  // namespace brdf::daemon
