// InterpolateLoop: the threads that serve Interpolate, the call analysis clients make by the
// thousand, on gRPC's completion-queue (async) API.
//
// Why threads of our own: gRPC's callback API (where Interpolate ran before) runs calls on its
// "nexting" threads, at least two however few the cores. Under a stream of calls they never
// sleep, and with clients on the same two cores the busy threads outnumber the cores: the
// scheduler then shares the cores out in whole ticks (4 ms at HZ=250), and a call whose next step
// waits on a thread that is out of turn waits that long. That, not the answer (microseconds), was
// the Interpolate tail (bench/daemon, README "Performance"). Here a loop thread polls its own
// completion queue, so it reads a request, answers it and queues the reply itself: one busy
// thread per loop, as many loops as `threads`.
//
// A loop never blocks on the store or an index build: a query whose index is current
// (InterpolationService::AnswerIfReady) is answered on the spot; one that must first load,
// extend or build the index (a session's first query, the first after a reading lands) goes to
// the slow lane, one thread that answers such queries in arrival order, so the loops go on
// answering every other query meanwhile.
//
// Lifecycle, with the grpc::Server it serves (server.cc):
//   loop.AddQueues(builder); server = builder.BuildAndStart(); loop.Start();
//   ... loop.BeginShutdown(); server->Shutdown(deadline); loop.Stop();
#pragma once

#include <grpcpp/server_builder.h>

#include <deque>
#include <memory>
#include <thread>
#include <vector>

#include "core/mutex.h"
#include "daemon/api/interpolation.h"

namespace brdf::daemon {

class InterpolateLoop {
 public:
  // `service` must outlive the loop. threads ≥ 1. With `cpus`, thread i runs on CPU
  // cpus[i % cpus.size()] only (a thread that cannot be pinned logs a warning and runs unpinned).
  InterpolateLoop(InterpolationService& service, int threads, std::vector<int> cpus = {});
  ~InterpolateLoop();  // Stop()
  InterpolateLoop(const InterpolateLoop&) = delete;
  InterpolateLoop& operator=(const InterpolateLoop&) = delete;

  int threads() const { return threads_; }

  // One completion queue per thread, added before the server is built.
  void AddQueues(grpc::ServerBuilder& builder);
  // After BuildAndStart: asks for the first calls and starts the threads.
  void Start();
  // Before grpc::Server::Shutdown: from here on no new call is asked for.
  void BeginShutdown();
  // After grpc::Server::Shutdown: the slow lane answers what it holds, the queues are shut down
  // and drained, the threads joined. Idempotent.
  void Stop();

 private:
  struct Call;

  void Serve(grpc::ServerCompletionQueue* queue);
  void SlowLane();
  // Asks gRPC for the next Interpolate call on `queue` (nothing once BeginShutdown was called).
  void Request(grpc::ServerCompletionQueue* queue);
  static void Finish(Call* call, const grpc::Status& status);

  InterpolationService& service_;
  const int threads_;
  const std::vector<int> cpus_;
  std::vector<std::unique_ptr<grpc::ServerCompletionQueue>> queues_;
  std::vector<std::thread> loops_;

  Mutex request_mu_;  // orders Request against BeginShutdown
  bool closing_ GUARDED_BY(request_mu_) = false;

  Mutex slow_mu_;
  CondVar slow_cv_;
  std::deque<Call*> slow_ GUARDED_BY(slow_mu_);
  bool slow_stop_ GUARDED_BY(slow_mu_) = false;
  std::thread slow_lane_;
  bool stopped_ = false;
};

}  // namespace brdf::daemon
