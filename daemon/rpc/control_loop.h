// ControlLoop: the threads that serve the control plane -- the operator's verbs (SubmitPlan,
// StartSession, PauseSession, ResumeSession, AbortSession, AnswerPrompt), GetRigStatus and the
// health service's Check -- on gRPC's completion-queue (async) API, apart from the synchronous
// pool that runs the streams and the analysts' other calls.
//
// Why a pool of their own: on the synchronous API every call, a stream included, holds one of
// the pool's threads for as long as it lasts; analysts' streams could take them all, and then
// PauseSession failed with "Server Threadpool Exhausted" (issue 20). Here the control calls are
// read from their own completion queue by their own threads, so whatever the streams hold, a
// control call waits only for the control calls ahead of it. The streams are capped besides
// (stream_registry.h), so the synchronous pool is never exhausted either. The threads ask for nice
// -5 (CAP_SYS_NICE or RLIMIT_NICE: the systemd unit's LimitNICE=-5; else they stay at 0) and a
// slice of 0.1 ms, so a woken control thread preempts a running analyst's thread instead of
// waiting out its slice; the streams' work runs at +10: with the cores busy (Interpolate clients,
// exports), a control call still gets one at once (thread_priority.h,
// bench/daemon/control_plane.sh).
//
// Each method is added with Add() before the server is built, from a service that marked it
// async (WithAsyncMethod_X) and a handler with the synchronous signature (the service's own
// method). Lifecycle, with the grpc::Server it serves (server.cc):
//   loop.Add(...)...; loop.AddQueue(builder); server = builder.BuildAndStart(); loop.Start();
//   ... loop.BeginShutdown(); server->Shutdown(deadline); loop.Stop();
#pragma once

#include <grpcpp/server_builder.h>
#include <grpcpp/server_context.h>
#include <grpcpp/support/async_unary_call.h>

#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include "core/mutex.h"

namespace brdf::daemon {

class ControlLoop {
 public:
  // Asks gRPC for the next call of one method (the service's RequestX).
  template <class Request, class Response>
  using RequestFn =
      std::function<void(grpc::ServerContext*, Request*, grpc::ServerAsyncResponseWriter<Response>*,
                         grpc::ServerCompletionQueue*, void* tag)>;
  // Answers one call (the service's synchronous method).
  template <class Request, class Response>
  using HandleFn = std::function<grpc::Status(grpc::ServerContext*, const Request*, Response*)>;

  // threads ≥ 1.
  explicit ControlLoop(int threads);
  ~ControlLoop();  // Stop()
  ControlLoop(const ControlLoop&) = delete;
  ControlLoop& operator=(const ControlLoop&) = delete;

  int threads() const { return threads_; }

  // Serves one method. Before Start().
  template <class Request, class Response>
  void Add(RequestFn<Request, Response> request, HandleFn<Request, Response> handle) {
    methods_.push_back(
        std::make_unique<Method<Request, Response>>(this, std::move(request), std::move(handle)));
  }

  // The completion queue, added before the server is built.
  void AddQueue(grpc::ServerBuilder& builder);
  // After BuildAndStart: asks for the first call of every method and starts the threads.
  void Start();
  // Before grpc::Server::Shutdown: from here on no new call is asked for.
  void BeginShutdown();
  // After grpc::Server::Shutdown: the queue is shut down and drained, the threads joined.
  // Idempotent.
  void Stop();

 private:
  // One call in flight: its own tag.
  struct Call {
    virtual ~Call() = default;
    // The call arrived (ok) or its reply completed; false: delete it.
    virtual bool Proceed(bool ok) = 0;
  };
  struct MethodBase {
    virtual ~MethodBase() = default;
    virtual void Ask() = 0;  // asks gRPC for one more call
  };

  template <class Request, class Response>
  struct Method final : MethodBase {
    Method(ControlLoop* l, RequestFn<Request, Response> r, HandleFn<Request, Response> h)
        : loop(l), request(std::move(r)), handle(std::move(h)) {}
    void Ask() override;
    ControlLoop* loop;
    RequestFn<Request, Response> request;
    HandleFn<Request, Response> handle;
  };

  template <class Request, class Response>
  struct UnaryCall final : Call {
    explicit UnaryCall(Method<Request, Response>* m) : method(m), responder(&context) {}
    bool Proceed(bool ok) override {
      if (finishing || !ok) return false;  // the reply completed, or the shutdown cancelled it
      method->Ask();                       // the next call, asked for before this one is answered
      const grpc::Status status = method->handle(&context, &request, &response);
      finishing = true;
      if (status.ok()) {
        responder.Finish(response, status, this);
      } else {
        responder.FinishWithError(status, this);
      }
      return true;
    }
    Method<Request, Response>* method;
    grpc::ServerContext context;
    Request request;
    Response response;
    grpc::ServerAsyncResponseWriter<Response> responder;
    bool finishing = false;
  };

  // True when a new call may be asked for (not closing); holds request_mu_ while `ask` runs.
  bool AskIfOpen(const std::function<void()>& ask);
  void Serve();

  const int threads_;
  std::vector<std::unique_ptr<MethodBase>> methods_;
  std::unique_ptr<grpc::ServerCompletionQueue> queue_;
  std::vector<std::thread> loops_;
  Mutex request_mu_;  // orders Request against BeginShutdown
  bool closing_ GUARDED_BY(request_mu_) = false;
  bool stopped_ = false;
};

template <class Request, class Response>
void ControlLoop::Method<Request, Response>::Ask() {
  loop->AskIfOpen([this] {
    auto* call = new UnaryCall<Request, Response>(this);
    this->request(&call->context, &call->request, &call->responder, loop->queue_.get(),
                  static_cast<Call*>(call));
  });
}

}  // namespace brdf::daemon
