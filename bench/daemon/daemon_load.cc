// bench_daemon_load: Interpolate latency and throughput against a running brdfd, from N concurrent
// clients (each its own channel, i.e. its own HTTP/2 connection, as separate analysis programs
// would be), each calling Interpolate back to back with a random direction for `--seconds`.
// Latency is the client's: from the call to the answer, over loopback.
//
// --api chooses the client side of gRPC. "queue" (the default): all clients on one thread with
// gRPC's completion-queue API, each client's next call started by that thread when the previous
// one completes. The load generator then needs one core at most and never competes with itself
// for the two this machine has (brdfd's Interpolate loop takes the other): a load generator of
// several busy threads on the same cores as the server measures the scheduler's time slices
// (4 ms ticks) rather than the server. "callback": gRPC's callback API, each next call started on
// the gRPC thread that read the previous answer (gRPC runs two or more such threads: the
// multi-threaded client). "sync": one blocking thread per client (the simplest analysis
// program); needed for --rate.
//
// --rate R paces each client at R calls/s on a fixed schedule (an analysis program's pace rather
// than a saturating loop). Latency is then measured from each call's scheduled time, so a call that
// starts late because the previous one was slow counts its wait (no coordinated omission).
//
// With --recording SESSION the tool also reads that session's progress before and after the
// window and prints how many steps it completed meanwhile (proof that it was recording).
//
// --noop (queue API): every other call of each client is the no-op instead of an Interpolate, so
// that both see the same load in the same window, and the line adds the no-op's percentiles and
// p99_ratio = Interpolate p99 ÷ no-op p99 (absolute times on a shared machine do not hold; the
// ratio does). The no-op is an Interpolate of the same session with no direction: brdfd's
// Interpolate loop reads it, authorizes the token, parses it and answers INVALID_ARGUMENT before
// any index lookup, so it travels Interpolate's own path (the completion-queue loop thread, the
// same connections) minus the interpolation. A separate RPC (grpc.health.v1 Check) would be
// served by other threads (the synchronous API's pool) and measure another path.
//
// Output: one "key=value" line (bench/daemon/run.sh parses it).
#include <absl/synchronization/mutex.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/support/client_callback.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string address;
  std::string token;
  std::string session;
  std::string recording;
  int clients = 8;
  double seconds = 10;
  double warmup = 1;
  double rate = 0;  // calls/s per client; 0: back to back
  std::string api = "queue";
  bool noop = false;  // every other call of each client the no-op (--noop)
};

void Authorize(grpc::ClientContext& context, const Options& o) {
  if (!o.token.empty()) context.AddMetadata("authorization", "Bearer " + o.token);
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
}

// Done steps of `session` (−1 when it cannot be read).
long DoneSteps(const std::shared_ptr<grpc::Channel>& channel, const Options& o,
               const std::string& session) {
  auto stub = brdf::v1::Control::NewStub(channel);
  grpc::ClientContext context;
  Authorize(context, o);
  brdf::v1::GetSessionRequest request;
  request.set_session_id(session);
  brdf::v1::Session response;
  if (!stub->GetSession(&context, request, &response).ok()) return -1;
  return static_cast<long>(response.progress().done_steps());
}

struct ClientResult {
  std::vector<double> latencies_us;
  long errors = 0;
  std::string first_error;
};

// An Interpolation stub on a channel of its own (its own HTTP/2 connection, as a separate analysis
// program would have).
std::unique_ptr<brdf::v1::Interpolation::Stub> OwnConnectionStub(const std::string& address) {
  grpc::ChannelArguments args;
  args.SetInt("grpc.use_local_subchannel_pool", 1);
  return brdf::v1::Interpolation::NewStub(
      grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args));
}

// A random direction of the benchmark's range (θi, θo in [0, 70], φ in [0, 180]) into `request`.
void RandomDirection(std::mt19937_64& rng, brdf::v1::InterpolateRequest* request) {
  std::uniform_real_distribution<double> theta(0, 70);
  std::uniform_real_distribution<double> phi(0, 180);
  brdf::v1::IsoDirection* iso = request->mutable_direction()->mutable_iso();
  iso->set_theta_i(theta(rng));
  iso->set_theta_o(theta(rng));
  iso->set_phi(phi(rng));
}

// Counts a call that started at `start` and ended at `end`, unless it started in the warm-up
// (connections, the index's first build).
void Record(ClientResult* out, Clock::time_point measure_from, Clock::time_point start,
            Clock::time_point end, const grpc::Status& status) {
  if (start < measure_from) return;
  if (!status.ok()) {
    if (out->errors++ == 0) out->first_error = status.error_message();
    return;
  }
  out->latencies_us.push_back(std::chrono::duration<double, std::micro>(end - start).count());
}

void Client(const Options& o, int seed, Clock::time_point measure_from, Clock::time_point until,
            ClientResult* out) {
  auto stub = OwnConnectionStub(o.address);
  std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
  out->latencies_us.reserve(200000);
  const bool paced = o.rate > 0;
  const auto period =
      paced
          ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate))
          : Clock::duration::zero();
  // Clients start at staggered offsets so paced calls do not arrive in bursts of N.
  Clock::time_point next = Clock::now() + period * (seed % 97) / 97;
  while (Clock::now() < until) {
    if (paced) std::this_thread::sleep_until(next);
    brdf::v1::InterpolateRequest request;
    request.set_session_id(o.session);
    RandomDirection(rng, &request);
    brdf::v1::InterpolateResponse response;
    grpc::ClientContext context;
    Authorize(context, o);
    const Clock::time_point start = paced ? next : Clock::now();
    if (paced) next += period;
    const grpc::Status status = stub->Interpolate(&context, request, &response);
    Record(out, measure_from, start, Clock::now(), status);
  }
}

// One client on gRPC's callback API: a closed loop of calls, the next started by the completion
// of the previous one. The request and response messages are reused (gRPC parses into a cleared
// message); the ClientContext cannot be, so each call has a new one.
class CallbackClient {
 public:
  CallbackClient(const Options& o, int seed, Clock::time_point measure_from,
                 Clock::time_point until, ClientResult* out)
      : o_(o),
        rng_(static_cast<std::uint64_t>(seed)),
        measure_from_(measure_from),
        until_(until),
        out_(out) {
    stub_ = OwnConnectionStub(o.address);
    out_->latencies_us.reserve(200000);
    request_.set_session_id(o.session);
  }

  void Start() { Call(); }

  // Blocks until the loop has ended (the window is over and the last call is back).
  void Wait() {
    absl::MutexLock lock(&mu_);
    mu_.Await(absl::Condition(&done_));
  }

 private:
  void Call() {
    RandomDirection(rng_, &request_);
    context_ = std::make_unique<grpc::ClientContext>();
    Authorize(*context_, o_);
    start_ = Clock::now();
    stub_->async()->Interpolate(context_.get(), &request_, &response_,
                                [this](grpc::Status status) { Done(status); });
  }

  void Done(const grpc::Status& status) {
    const Clock::time_point end = Clock::now();
    Record(out_, measure_from_, start_, end, status);
    if (end < until_) {
      Call();
      return;
    }
    absl::MutexLock lock(&mu_);
    done_ = true;
  }

  const Options& o_;
  std::unique_ptr<brdf::v1::Interpolation::Stub> stub_;
  std::mt19937_64 rng_;
  const Clock::time_point measure_from_;
  const Clock::time_point until_;
  ClientResult* out_;
  brdf::v1::InterpolateRequest request_;
  brdf::v1::InterpolateResponse response_;
  std::unique_ptr<grpc::ClientContext> context_;
  Clock::time_point start_;
  absl::Mutex mu_;
  bool done_ = false;
};

// All clients on ONE thread with gRPC's completion-queue API: each client (its own channel) keeps
// one call in flight, and the thread that takes a call's completion from the queue records it
// and starts that client's next call. One thread does all the load generator's work, so on a
// 2-core machine shared with brdfd it never competes with itself for a core (see --api).
class QueueClients {
 public:
  // With `noop_results` (one per client, or null), every other call is the no-op (--noop).
  QueueClients(const Options& o, Clock::time_point measure_from, Clock::time_point until,
               std::vector<ClientResult>* results, std::vector<ClientResult>* noop_results)
      : o_(o), measure_from_(measure_from), until_(until) {
    for (std::size_t i = 0; i < results->size(); ++i) {
      auto client = std::make_unique<Client>();
      client->noop_out = noop_results == nullptr ? nullptr : &(*noop_results)[i];
      if (client->noop_out != nullptr) client->noop_out->latencies_us.reserve(200000);
      client->stub = OwnConnectionStub(o.address);
      client->rng.seed(1000 + i);
      client->out = &(*results)[i];
      client->out->latencies_us.reserve(200000);
      client->request.set_session_id(o.session);
      client->noop_request.set_session_id(o.session);
      clients_.push_back(std::move(client));
    }
  }

  // Runs the closed loops until the window is over and every call is back.
  void Run() {
    int in_flight = 0;
    for (auto& c : clients_) {
      Call(*c);
      ++in_flight;
    }
    void* tag = nullptr;
    bool ok = false;
    while (in_flight > 0 && queue_.Next(&tag, &ok)) {
      Client& c = *static_cast<Client*>(tag);
      const Clock::time_point end = Clock::now();
      if (c.noop) {
        // The no-op's expected answer is the refusal; anything else is an error.
        const grpc::Status st = c.status.error_code() == grpc::StatusCode::INVALID_ARGUMENT
                                    ? grpc::Status::OK
                                    : grpc::Status(grpc::StatusCode::UNKNOWN,
                                                   "no-op answered " + c.status.error_message());
        Record(c.noop_out, measure_from_, c.start, end, st);
      } else {
        Record(c.out, measure_from_, c.start, end, c.status);
      }
      if (end < until_) {
        Call(c);
      } else {
        --in_flight;
      }
    }
    queue_.Shutdown();
    while (queue_.Next(&tag, &ok)) {
    }
  }

 private:
  struct Client {
    std::unique_ptr<brdf::v1::Interpolation::Stub> stub;
    std::mt19937_64 rng;
    ClientResult* out = nullptr;
    ClientResult* noop_out = nullptr;  // --noop only
    bool noop = false;                 // the call in flight is the no-op
    brdf::v1::InterpolateRequest request;
    brdf::v1::InterpolateRequest noop_request;  // the session, no direction
    brdf::v1::InterpolateResponse response;
    std::unique_ptr<grpc::ClientContext> context;
    std::unique_ptr<grpc::ClientAsyncResponseReader<brdf::v1::InterpolateResponse>> reader;
    grpc::Status status;
    Clock::time_point start;
  };

  void Call(Client& c) {
    c.noop = c.noop_out != nullptr && !c.noop;
    if (!c.noop) RandomDirection(c.rng, &c.request);
    c.context = std::make_unique<grpc::ClientContext>();
    Authorize(*c.context, o_);
    c.start = Clock::now();
    c.reader =
        c.stub->AsyncInterpolate(c.context.get(), c.noop ? c.noop_request : c.request, &queue_);
    c.reader->Finish(&c.response, &c.status, &c);
  }

  const Options& o_;
  const Clock::time_point measure_from_;
  const Clock::time_point until_;
  grpc::CompletionQueue queue_;
  std::vector<std::unique_ptr<Client>> clients_;
};

double Percentile(std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0;
  const std::size_t i = std::min(sorted.size() - 1, static_cast<std::size_t>(p * sorted.size()));
  return sorted[i];
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app("bench_daemon_load: Interpolate latency and throughput from concurrent clients");
  app.add_option("--address", o.address, "brdfd's host:port")->required();
  app.add_option("--token", o.token, "bearer token (analyst is enough)");
  app.add_option("--session", o.session, "session to interpolate")->required();
  app.add_option("--recording", o.recording, "a session that records meanwhile (progress shown)");
  app.add_option("--clients", o.clients, "concurrent clients")->check(CLI::Range(1, 256));
  app.add_option("--seconds", o.seconds, "measurement window")->check(CLI::Range(0.1, 600.0));
  app.add_option("--warmup", o.warmup, "seconds before the window")->check(CLI::Range(0.0, 60.0));
  app.add_option("--rate", o.rate, "calls/s per client on a fixed schedule (0: back to back)")
      ->check(CLI::Range(0.0, 100000.0));
  app.add_option(
         "--api", o.api,
         "gRPC client API: queue (default: one thread), callback or sync (needed for --rate)")
      ->check(CLI::IsMember({"callback", "sync", "queue"}));
  app.add_flag("--noop", o.noop,
               "every other call the no-op (an Interpolate refused before any work; queue API): "
               "adds its percentiles and p99_ratio");
  CLI11_PARSE(app, argc, argv);
  if (o.noop && o.api != "queue") {
    std::fprintf(stderr, "bench_daemon_load: --noop needs --api queue\n");
    return 2;
  }
  if (o.rate > 0 && o.api != "sync") {
    std::fprintf(stderr, "bench_daemon_load: --rate needs --api sync\n");
    return 2;
  }
  // As brdfd does (daemon/api/server.cc): Debian's Abseil keeps absl::Mutex's debug-only deadlock
  // graph on, a cost on every lock gRPC takes that upstream release builds do not pay.
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);

  auto control_channel = grpc::CreateChannel(o.address, grpc::InsecureChannelCredentials());
  const Clock::time_point measure_from =
      Clock::now() +
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.warmup));
  const Clock::time_point until = measure_from + std::chrono::duration_cast<Clock::duration>(
                                                     std::chrono::duration<double>(o.seconds));

  std::vector<ClientResult> results(static_cast<std::size_t>(o.clients));
  std::vector<ClientResult> noop_results(o.noop ? results.size() : 0);
  std::vector<std::thread> threads;
  std::vector<std::unique_ptr<CallbackClient>> callback_clients;
  std::unique_ptr<QueueClients> queue_clients;
  if (o.api == "queue") {
    queue_clients = std::make_unique<QueueClients>(o, measure_from, until, &results,
                                                   o.noop ? &noop_results : nullptr);
  } else {
    for (int i = 0; i < o.clients; ++i) {
      ClientResult* out = &results[static_cast<std::size_t>(i)];
      if (o.api == "sync") {
        threads.emplace_back(Client, std::cref(o), 1000 + i, measure_from, until, out);
      } else {
        callback_clients.push_back(
            std::make_unique<CallbackClient>(o, 1000 + i, measure_from, until, out));
      }
    }
  }
  for (auto& c : callback_clients) c->Start();
  std::thread queue_thread;
  if (queue_clients) queue_thread = std::thread([&] { queue_clients->Run(); });
  std::this_thread::sleep_until(measure_from);
  const long before = o.recording.empty() ? -1 : DoneSteps(control_channel, o, o.recording);
  for (std::thread& t : threads) t.join();
  for (auto& c : callback_clients) c->Wait();
  if (queue_thread.joinable()) queue_thread.join();
  const long after = o.recording.empty() ? -1 : DoneSteps(control_channel, o, o.recording);

  // All clients' latencies, sorted; errors counted and the first one kept.
  struct Merged {
    std::vector<double> latencies_us;
    long errors = 0;
    std::string first_error;
  };
  auto merge = [](std::vector<ClientResult>& from) {
    Merged m;
    for (ClientResult& r : from) {
      m.latencies_us.insert(m.latencies_us.end(), r.latencies_us.begin(), r.latencies_us.end());
      if (r.errors > 0 && m.first_error.empty()) m.first_error = r.first_error;
      m.errors += r.errors;
    }
    std::sort(m.latencies_us.begin(), m.latencies_us.end());
    return m;
  };
  Merged interpolate = merge(results);
  Merged noop = merge(noop_results);
  std::vector<double>& all = interpolate.latencies_us;
  const long errors = interpolate.errors + noop.errors;
  const std::string first_error =
      interpolate.first_error.empty() ? noop.first_error : interpolate.first_error;
  std::string noop_fields;
  if (o.noop) {
    const double noop_p99 = Percentile(noop.latencies_us, 0.99);
    char buffer[256];
    std::snprintf(buffer, sizeof buffer,
                  " noop_calls=%zu noop_errors=%ld noop_p50_us=%.0f noop_p99_us=%.0f "
                  "p99_ratio=%.3f",
                  noop.latencies_us.size(), noop.errors, Percentile(noop.latencies_us, 0.5),
                  noop_p99, noop_p99 > 0 ? Percentile(all, 0.99) / noop_p99 : 0.0);
    noop_fields = buffer;
  }
  std::printf(
      "interpolate api=%s clients=%d calls=%zu errors=%ld qps=%.0f p50_us=%.0f p90_us=%.0f "
      "p99_us=%.0f "
      "p999_us=%.0f max_us=%.0f steps_recorded=%ld%s\n",
      o.api.c_str(), o.clients, all.size(), interpolate.errors,
      static_cast<double>(all.size()) / o.seconds, Percentile(all, 0.5), Percentile(all, 0.9),
      Percentile(all, 0.99), Percentile(all, 0.999), all.empty() ? 0.0 : all.back(),
      before >= 0 && after >= 0 ? after - before : -1, noop_fields.c_str());
  if (errors > 0) std::fprintf(stderr, "bench_daemon_load: first error: %s\n", first_error.c_str());
  return all.empty() || (o.noop && noop.latencies_us.empty()) ? 1 : 0;
}
