// bench_control_plane: does the operator keep control of a running brdfd whatever analysts do
// (issue 20)? Measures PauseSession and GetRigStatus latency on an idle daemon, then again while
// N analyst streams are open (WatchSession and StreamReadings read as they come, InterpolateBatch
// and Export never read) and 8 clients call Interpolate as fast as they can, in the same run.
// Prints one line of key=value figures: the medians and p99s of both phases, their ratios
// (loaded ÷ idle; issue 40's goal: ≤ 3 for the medians, ≤ 5 for the p99s), failed control calls,
// and how the streams fared (opened, refused by a cap).
//
// The operator's client runs in a process of its own (forked before any channel exists), as
// brdfctl or the web console do in the lab: in the analysts' process its calls would share gRPC's
// pollers with their 1,000 streams and 8 Interpolate threads, and measure that process's own
// queue (GetRigStatus 5-7x idle that way, 1.3x from its own process, brdfd alike). With
// --operator-in-load-process it measures from the analysts' process as before. The analysts'
// client threads run at nice 10, the operator's at 0.
//
// The session given by --pause-session must be PAUSED: each PauseSession is then a real call of
// the verb that answers "already paused" (a control call that changes nothing, so it can be
// repeated). bench/daemon/control_plane.sh sets up the daemon, the sessions and the tokens.
#include <grpcpp/grpcpp.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string address;
  std::string operator_token;
  std::string analyst_token;
  std::string pause_session;  // PAUSED
  std::string data_session;   // with readings: Interpolate, batches, exports
  int streams = 1000;
  int interpolate_clients = 8;
  int calls = 200;     // control calls per phase (half PauseSession, half GetRigStatus)
  double slow_ms = 0;  // > 0: each control call slower than this is printed to stderr
  bool operator_in_load_process = false;
};

std::unique_ptr<grpc::ClientContext> Context(const std::string& token, std::chrono::seconds d) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->AddMetadata("authorization", "Bearer " + token);
  context->set_deadline(std::chrono::system_clock::now() + d);
  return context;
}

std::shared_ptr<grpc::Channel> NewChannel(const std::string& address, int index) {
  grpc::ChannelArguments args;
  args.SetInt("brdf.bench.channel", index);  // a connection of its own
  args.SetMaxReceiveMessageSize(64 * 1024 * 1024);
  return grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
}

// The analysts' load runs at nice 10 in this process (the stream pump and the Interpolate
// clients): on the lab's network analysts run on their own machines, and here they would otherwise
// take the core the operator's client (the measuring thread, at 0) needs; what is measured is then
// brdfd's answer, not the load generator's queue in front of it. brdfd is loaded all the same.
void AsAnalystLoad() {
  (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 10);
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// Quantile q of `loaded` ÷ the same of `idle` (0 when idle has none).
double Ratio(const std::vector<double>& loaded, const std::vector<double>& idle, double q) {
  const double base = Quantile(idle, q);
  return base > 0 ? Quantile(loaded, q) / base : 0;
}

struct ControlFigures {
  std::vector<double> pause_ms, status_ms;
  int failed = 0;
  std::string first_failure;
};

// `calls` control calls, alternating PauseSession (deferred, on the paused session) and
// GetRigStatus, one at a time, 2 ms apart.
ControlFigures MeasureControl(const Options& o, brdf::v1::Control::Stub& control) {
  ControlFigures f;
  for (int i = 0; i < o.calls; ++i) {
    grpc::Status st;
    const auto begin = Clock::now();
    if (i % 2 == 0) {
      brdf::v1::PauseSessionRequest request;
      request.set_session_id(o.pause_session);
      request.set_mode(brdf::v1::PAUSE_MODE_DEFERRED);
      brdf::v1::PauseSessionResponse response;
      st = control.PauseSession(Context(o.operator_token, std::chrono::seconds(10)).get(), request,
                                &response);
      if (st.ok() && !response.already_paused()) {
        st = grpc::Status(grpc::StatusCode::FAILED_PRECONDITION, "the session was not paused");
      }
    } else {
      brdf::v1::RigStatus response;
      st = control.GetRigStatus(Context(o.operator_token, std::chrono::seconds(10)).get(), {},
                                &response);
    }
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - begin).count();
    if (o.slow_ms > 0 && ms > o.slow_ms) {
      // steady_clock is CLOCK_MONOTONIC: `perf record -k CLOCK_MONOTONIC` timestamps match.
      std::fprintf(stderr, "slow control call: %s %.3f ms from %.6f s (CLOCK_MONOTONIC)\n",
                   i % 2 == 0 ? "PauseSession" : "GetRigStatus", ms,
                   std::chrono::duration<double>(begin.time_since_epoch()).count());
    }
    if (!st.ok()) {
      if (f.failed++ == 0) {
        f.first_failure = std::to_string(st.error_code()) + " " + st.error_message();
      }
    } else {
      (i % 2 == 0 ? f.pause_ms : f.status_ms).push_back(ms);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return f;
}

// The operator's client in a process of its own: each byte its parent writes asks for one
// MeasureControl, whose figures come back over the other pipe.
class OperatorProcess {
 public:
  // Forks before the caller makes any gRPC channel (gRPC does not survive a fork).
  explicit OperatorProcess(const Options& o) {
    int ask[2], answer[2];
    if (::pipe(ask) != 0 || ::pipe(answer) != 0) Die("pipe");
    pid_ = ::fork();
    if (pid_ < 0) Die("fork");
    if (pid_ == 0) {
      ::close(ask[1]);
      ::close(answer[0]);
      Serve(o, ask[0], answer[1]);
      std::_Exit(0);
    }
    ::close(ask[0]);
    ::close(answer[1]);
    ask_ = ask[1];
    answer_ = answer[0];
  }
  ~OperatorProcess() {
    ::close(ask_);
    ::close(answer_);
    (void)::waitpid(pid_, nullptr, 0);
  }
  ControlFigures Measure() {
    const char go = 'm';
    WriteAll(ask_, &go, 1);
    ControlFigures f;
    f.pause_ms = ReadSeries(answer_);
    f.status_ms = ReadSeries(answer_);
    ReadAll(answer_, &f.failed, sizeof f.failed);
    std::size_t n = 0;
    ReadAll(answer_, &n, sizeof n);
    f.first_failure.resize(n);
    ReadAll(answer_, f.first_failure.data(), n);
    return f;
  }

 private:
  static void Die(const char* what) {
    std::perror(what);
    std::exit(2);
  }
  static void WriteAll(int fd, const void* data, std::size_t n) {
    const char* p = static_cast<const char*>(data);
    while (n > 0) {
      const ssize_t w = ::write(fd, p, n);
      if (w <= 0) Die("operator pipe (write)");
      p += w;
      n -= static_cast<std::size_t>(w);
    }
  }
  static void ReadAll(int fd, void* data, std::size_t n) {
    char* p = static_cast<char*>(data);
    while (n > 0) {
      const ssize_t r = ::read(fd, p, n);
      if (r <= 0) Die("operator pipe (read)");
      p += r;
      n -= static_cast<std::size_t>(r);
    }
  }
  static std::vector<double> ReadSeries(int fd) {
    std::size_t n = 0;
    ReadAll(fd, &n, sizeof n);
    std::vector<double> v(n);
    ReadAll(fd, v.data(), n * sizeof(double));
    return v;
  }
  static void WriteSeries(int fd, const std::vector<double>& v) {
    const std::size_t n = v.size();
    WriteAll(fd, &n, sizeof n);
    WriteAll(fd, v.data(), n * sizeof(double));
  }
  static void Serve(const Options& o, int ask, int answer) {
    auto control = brdf::v1::Control::NewStub(NewChannel(o.address, 0));
    char go = 0;
    while (::read(ask, &go, 1) == 1) {
      const ControlFigures f = MeasureControl(o, *control);
      WriteSeries(answer, f.pause_ms);
      WriteSeries(answer, f.status_ms);
      WriteAll(answer, &f.failed, sizeof f.failed);
      const std::size_t n = f.first_failure.size();
      WriteAll(answer, &n, sizeof n);
      WriteAll(answer, f.first_failure.data(), n);
    }
  }

  pid_t pid_ = -1;
  int ask_ = -1;
  int answer_ = -1;
};

// One analyst stream on the streams' completion queue.
struct Stream {
  virtual ~Stream() = default;
  virtual void Proceed(bool ok) = 0;
  virtual void Cancel() = 0;
  bool done = false;
  bool first_read = false;
  grpc::Status status;
};

template <class Message>
struct TypedStream final : Stream {
  enum State { kStarting, kReading, kFinishing };
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientAsyncReader<Message>> reader;
  Message message;
  bool read = false;  // false: never read after the start
  std::atomic<State> state{kStarting};

  void Proceed(bool ok) override {
    switch (state) {
      case kStarting:
        if (!read) return;  // held open, never read
        state = kReading;
        reader->Read(&message, this);
        return;
      case kReading:
        if (ok) {
          first_read = true;
          reader->Read(&message, this);
          return;
        }
        state = kFinishing;
        reader->Finish(&status, this);
        return;
      case kFinishing:
        done = true;
        return;
    }
  }
  // Ends the stream; one never read is finished here, so that how it ended (a refusal by the
  // memory budget or a stream cap: RESOURCE_EXHAUSTED) is counted as for the others.
  void Cancel() override {
    if (!read) {  // Finish first: after TryCancel the status would be CANCELLED
      state = kFinishing;
      reader->Finish(&status, this);
    }
    context.TryCancel();
  }
};

template <class Message, class Request, class Prepare>
std::unique_ptr<Stream> Open(const std::string& token, bool read, const Request& request,
                             grpc::CompletionQueue* cq, Prepare prepare) {
  auto s = std::make_unique<TypedStream<Message>>();
  s->context.AddMetadata("authorization", "Bearer " + token);
  s->read = read;
  s->reader = prepare(&s->context, request, cq);
  s->reader->StartCall(s.get());
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"bench_control_plane: control-call latency under 1,000 analyst streams"};
  app.add_option("--address", o.address)->required();
  app.add_option("--operator-token", o.operator_token)->required();
  app.add_option("--analyst-token", o.analyst_token)->required();
  app.add_option("--pause-session", o.pause_session, "a PAUSED session")->required();
  app.add_option("--data-session", o.data_session, "a session with readings")->required();
  app.add_option("--streams", o.streams);
  app.add_option("--interpolate-clients", o.interpolate_clients);
  app.add_option("--calls", o.calls);
  app.add_option("--slow-ms", o.slow_ms,
                 "print each control call slower than this (ms) with its start, to correlate");
  app.add_flag("--operator-in-load-process", o.operator_in_load_process,
               "measure the control calls from the analysts' process (shares its gRPC pollers)");
  CLI11_PARSE(app, argc, argv);
  using namespace brdf::v1;

  // The operator's calls: from its own process (forked first) or from this one.
  std::unique_ptr<OperatorProcess> operator_process;
  std::unique_ptr<Control::Stub> control;
  if (o.operator_in_load_process) {
    control = Control::NewStub(NewChannel(o.address, 0));
  } else {
    operator_process = std::make_unique<OperatorProcess>(o);
  }
  auto measure = [&] {
    return operator_process ? operator_process->Measure() : MeasureControl(o, *control);
  };
  // Warm-up, then the idle daemon.
  (void)measure();
  const ControlFigures idle = measure();

  // The streams, over 8 connections (gRPC caps concurrent streams per connection at 100 by
  // default on the client side: 1,000 streams need ≥ 10 connections; 16 to be safe).
  std::vector<std::shared_ptr<grpc::Channel>> channels;
  for (int c = 0; c < 16; ++c) channels.push_back(NewChannel(o.address, 100 + c));
  grpc::CompletionQueue cq;
  std::vector<std::unique_ptr<Stream>> streams;
  std::atomic<bool> stop{false};
  std::thread pump([&] {
    AsAnalystLoad();
    void* tag = nullptr;
    bool ok = false;
    while (cq.Next(&tag, &ok)) static_cast<Stream*>(tag)->Proceed(ok);
  });
  int kinds[4] = {0, 0, 0, 0};
  for (int i = 0; i < o.streams; ++i) {
    auto& channel = channels[static_cast<std::size_t>(i) % channels.size()];
    const int kind = i % 10 < 4 ? 0 : i % 10 < 7 ? 1 : i % 10 < 9 ? 2 : 3;
    ++kinds[kind];
    if (kind == 0) {  // WatchSession, read
      WatchSessionRequest r;
      r.set_session_id(o.pause_session);
      auto stub = Control::NewStub(channel);
      streams.push_back(Open<SessionEvent>(
          o.analyst_token, true, r, &cq,
          [&](grpc::ClientContext* c, const WatchSessionRequest& q, grpc::CompletionQueue* cq2) {
            return stub->PrepareAsyncWatchSession(c, q, cq2);
          }));
    } else if (kind == 1) {  // StreamReadings with follow, read
      StreamReadingsRequest r;
      r.set_session_id(o.pause_session);
      r.set_follow(true);
      auto stub = Data::NewStub(channel);
      streams.push_back(Open<Reading>(
          o.analyst_token, true, r, &cq,
          [&](grpc::ClientContext* c, const StreamReadingsRequest& q, grpc::CompletionQueue* cq2) {
            return stub->PrepareAsyncStreamReadings(c, q, cq2);
          }));
    } else if (kind == 2) {  // InterpolateBatch of 2,000 directions, never read
      InterpolateBatchRequest r;
      r.set_session_id(o.data_session);
      for (int d = 0; d < 2000; ++d) {
        IsoDirection* at = r.add_directions()->mutable_iso();
        at->set_theta_i(10 + d % 60);
        at->set_theta_o(20 + (d / 60) % 50);
        at->set_phi(d % 180);
      }
      auto stub = Interpolation::NewStub(channel);
      streams.push_back(
          Open<InterpolateBatchChunk>(o.analyst_token, false, r, &cq,
                                      [&](grpc::ClientContext* c, const InterpolateBatchRequest& q,
                                          grpc::CompletionQueue* cq2) {
                                        return stub->PrepareAsyncInterpolateBatch(c, q, cq2);
                                      }));
    } else {  // Export of the readings as CSV, never read
      ExportRequest r;
      r.set_session_id(o.data_session);
      r.set_format(EXPORT_FORMAT_READINGS_CSV);
      auto stub = Data::NewStub(channel);
      streams.push_back(Open<ExportChunk>(
          o.analyst_token, false, r, &cq,
          [&](grpc::ClientContext* c, const ExportRequest& q, grpc::CompletionQueue* cq2) {
            return stub->PrepareAsyncExport(c, q, cq2);
          }));
    }
  }
  std::this_thread::sleep_for(std::chrono::seconds(3));  // the streams settle

  // 8 Interpolate clients, as fast as they can.
  std::atomic<long> interpolations{0}, interpolate_failures{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < o.interpolate_clients; ++c) {
    clients.emplace_back([&, c] {
      AsAnalystLoad();
      auto stub = Interpolation::NewStub(NewChannel(o.address, 1000 + c));
      for (long n = c; !stop; ++n) {
        InterpolateRequest r;
        r.set_session_id(o.data_session);
        IsoDirection* at = r.mutable_direction()->mutable_iso();
        at->set_theta_i(10 + static_cast<double>(n % 60));
        at->set_theta_o(20 + static_cast<double>((n / 60) % 50));
        at->set_phi(static_cast<double>(n % 180));
        InterpolateResponse answer;
        const grpc::Status st =
            stub->Interpolate(Context(o.analyst_token, std::chrono::seconds(10)).get(), r, &answer);
        st.ok() ? ++interpolations : ++interpolate_failures;
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto loaded_begin = Clock::now();
  const ControlFigures loaded = measure();
  const double loaded_s = std::chrono::duration<double>(Clock::now() - loaded_begin).count();
  const long interpolated = interpolations.load();
  stop = true;
  for (std::thread& t : clients) t.join();

  int first_read = 0;
  for (auto& s : streams) first_read += s->first_read ? 1 : 0;
  for (auto& s : streams) s->Cancel();
  // Let the finishing reads complete, then collect how each stream ended.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  cq.Shutdown();
  pump.join();
  int refused = 0;
  std::string refusal;
  for (auto& s : streams) {
    if (s->done && s->status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) {
      if (refused++ == 0) refusal = s->status.error_message();
    }
  }

  const double ip50 = Quantile(idle.pause_ms, 0.5), is50 = Quantile(idle.status_ms, 0.5);
  const double lp50 = Quantile(loaded.pause_ms, 0.5), ls50 = Quantile(loaded.status_ms, 0.5);
  std::printf(
      "streams=%d (watch %d, readings %d, batch-unread %d, export-unread %d) read_streams_open=%d "
      "refused=%d interpolate_clients=%d interpolate_calls_s=%.0f interpolate_failures=%ld "
      "idle_pause_p50_ms=%.3f idle_pause_p99_ms=%.3f idle_status_p50_ms=%.3f "
      "idle_status_p99_ms=%.3f loaded_pause_p50_ms=%.3f loaded_pause_p99_ms=%.3f "
      "loaded_status_p50_ms=%.3f loaded_status_p99_ms=%.3f pause_ratio=%.2f status_ratio=%.2f "
      "pause_p99_ratio=%.2f status_p99_ratio=%.2f control_failed=%d operator=%s%s%s\n",
      o.streams, kinds[0], kinds[1], kinds[2], kinds[3], first_read, refused, o.interpolate_clients,
      static_cast<double>(interpolated) / loaded_s, interpolate_failures.load(), ip50,
      Quantile(idle.pause_ms, 0.99), is50, Quantile(idle.status_ms, 0.99), lp50,
      Quantile(loaded.pause_ms, 0.99), ls50, Quantile(loaded.status_ms, 0.99),
      ip50 > 0 ? lp50 / ip50 : 0, is50 > 0 ? ls50 / is50 : 0,
      Ratio(loaded.pause_ms, idle.pause_ms, 0.99), Ratio(loaded.status_ms, idle.status_ms, 0.99),
      idle.failed + loaded.failed, o.operator_in_load_process ? "load-process" : "own-process",
      idle.failed + loaded.failed > 0 ? " first_failure=" : "",
      (idle.first_failure + loaded.first_failure).c_str());
  if (refused > 0) std::fprintf(stderr, "a refused stream: %s\n", refusal.c_str());
  return idle.failed + loaded.failed == 0 ? 0 : 1;
}
