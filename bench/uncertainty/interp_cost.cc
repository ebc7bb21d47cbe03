// bench_interp_uncertainty: what asking for uncertainties costs Interpolate and InterpolateBatch
// (issue 37: at most 1.5× the time without), against a running brdfd and one session, in the same
// run: each repetition times the same calls with and without include_uncertainty, in alternating
// order, and the medians and their ratio are printed.
//   Interpolate:      --calls sequential unary calls at random directions (one client thread);
//   InterpolateBatch: one call of --directions random directions, every chunk read (its answers
//                     carry the measurement and interpolation parts; --shared: the shared part
//                     too).
// Directions: θi, θo uniform in [0, --theta-max], φ in [0, 180], from --seed, kept only where the
// method gives a spectrum (an answer that is not OK carries no uncertainty and would only dilute
// the cost; --all-directions keeps them all). The share of OK answers is printed.
//
// With --daemon-pid, each batch's CPU time is split too: the daemon's (all its threads, from
// /proc/<pid>/task/*/schedstat: evaluating, building and sending the answers) and this client's
// (receiving and parsing them), medians beside the wall-clock ones.
//
// With --dump FILE, one more batch with every part (include_uncertainty and _shared) is written
// to FILE, its chunks serialised one after the other, to compare two builds' answers (cmp).
//
// Output: "key=value" lines, then a summary table (bench/uncertainty/interp_cost.sh).
#include <grpcpp/grpcpp.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"

namespace {

using Clock = std::chrono::steady_clock;
namespace v1 = brdf::v1;

struct Setup {
  std::string session;
  std::string token;
  v1::InterpolationMethod method = v1::INTERPOLATION_METHOD_OCTANT;
  std::vector<v1::DirectionQuery> directions;
  bool shared = false;  // InterpolateBatch: include_uncertainty_shared
  int daemon_pid = 0;   // 0: the daemon's CPU time is not measured
};

// CPU seconds a batch took: the daemon's (-1: not measured) and this process's.
struct CpuSpent {
  double daemon = -1;
  double client = 0;
};

// CPU seconds process `pid` has run so far, all its threads (schedstat's first field, ns); -1
// when unreadable.
double ProcessCpuSeconds(int pid) {
  std::error_code ec;
  const std::filesystem::path tasks = "/proc/" + std::to_string(pid) + "/task";
  double total = 0;
  bool any = false;
  for (const auto& task : std::filesystem::directory_iterator(tasks, ec)) {
    std::ifstream in(task.path() / "schedstat");
    double ns = 0;
    if (in >> ns) {
      total += ns * 1e-9;
      any = true;
    }
  }
  return any && !ec ? total : -1;
}

double OwnCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::vector<v1::DirectionQuery> RandomDirections(int n, double theta_max, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> theta(0, theta_max), phi(0, 180);
  std::vector<v1::DirectionQuery> out(static_cast<std::size_t>(n));
  for (v1::DirectionQuery& q : out) {
    q.mutable_iso()->set_theta_i(theta(rng));
    q.mutable_iso()->set_theta_o(theta(rng));
    q.mutable_iso()->set_phi(phi(rng));
  }
  return out;
}

void Authorize(grpc::ClientContext& context, const std::string& token) {
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
}

// Seconds for `calls` Interpolate calls; *ok counts the OK answers. -1 on an RPC error.
double TimeUnary(v1::Interpolation::Stub& stub, const Setup& s, int calls, bool uncertain,
                 int* ok) {
  v1::InterpolateRequest request;
  request.set_session_id(s.session);
  request.set_method(s.method);
  request.set_include_uncertainty(uncertain);
  v1::InterpolateResponse response;
  *ok = 0;
  const auto start = Clock::now();
  for (int i = 0; i < calls; ++i) {
    *request.mutable_direction() = s.directions[static_cast<std::size_t>(i) % s.directions.size()];
    grpc::ClientContext context;
    Authorize(context, s.token);
    const grpc::Status st = stub.Interpolate(&context, request, &response);
    if (!st.ok()) {
      std::fprintf(stderr, "Interpolate: %s\n", st.error_message().c_str());
      return -1;
    }
    *ok += response.result().status() == v1::INTERPOLATION_STATUS_OK ? 1 : 0;
  }
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Seconds for one InterpolateBatch of every direction; -1 on an RPC error. With `answered`, the
// directions whose answer is OK are appended to it.
double TimeBatch(v1::Interpolation::Stub& stub, const Setup& s, bool uncertain, int* ok,
                 std::vector<v1::DirectionQuery>* answered = nullptr,
                 std::uint64_t* bytes = nullptr, CpuSpent* cpu = nullptr) {
  v1::InterpolateBatchRequest request;
  request.set_session_id(s.session);
  request.set_method(s.method);
  request.set_include_uncertainty(uncertain);
  request.set_include_uncertainty_shared(s.shared);
  for (const v1::DirectionQuery& q : s.directions) *request.add_directions() = q;
  grpc::ClientContext context;
  Authorize(context, s.token);
  *ok = 0;
  const double daemon_before = s.daemon_pid > 0 ? ProcessCpuSeconds(s.daemon_pid) : -1;
  const double client_before = OwnCpuSeconds();
  const auto start = Clock::now();
  auto reader = stub.InterpolateBatch(&context, request);
  v1::InterpolateBatchChunk chunk;
  while (reader->Read(&chunk)) {
    if (bytes != nullptr) *bytes += chunk.ByteSizeLong();
    for (const v1::InterpolationResult& r : chunk.results()) {
      const bool good = r.status() == v1::INTERPOLATION_STATUS_OK;
      *ok += good ? 1 : 0;
      if (good && answered != nullptr) answered->push_back(r.query());
    }
  }
  const grpc::Status st = reader->Finish();
  if (!st.ok()) {
    std::fprintf(stderr, "InterpolateBatch: %s\n", st.error_message().c_str());
    return -1;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  if (cpu != nullptr) {
    cpu->client = OwnCpuSeconds() - client_before;
    const double daemon_after = daemon_before >= 0 ? ProcessCpuSeconds(s.daemon_pid) : -1;
    cpu->daemon = daemon_after >= 0 ? daemon_after - daemon_before : -1;
  }
  return wall;
}

// At least n random directions where the method answers (from rounds of 100,000 candidates, at
// most 20 rounds); empty on an RPC error.
std::vector<v1::DirectionQuery> AnsweredDirections(v1::Interpolation::Stub& stub, const Setup& s,
                                                   std::size_t n, double theta_max, unsigned seed) {
  std::vector<v1::DirectionQuery> answered;
  Setup probe = s;
  int ok = 0;
  for (unsigned round = 0; round < 20 && answered.size() < n; ++round) {
    probe.directions = RandomDirections(100000, theta_max, seed + 1000 * round);
    if (TimeBatch(stub, probe, false, &ok, &answered) < 0) return {};
  }
  if (answered.size() > n) answered.resize(n);
  return answered;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

// The bytes of the batch's chunks (as the client parsed them) per answer, without and with; not
// timed. False on an RPC error.
bool PrintBatchBytes(v1::Interpolation::Stub& stub, const Setup& batch, int directions) {
  std::uint64_t bytes[2] = {0, 0};
  int ok = 0;
  for (int k = 0; k < 2; ++k) {
    if (TimeBatch(stub, batch, k == 1, &ok, nullptr, &bytes[k]) < 0) return false;
  }
  std::printf("batch_bytes_per_answer without=%.0f with=%.0f ratio=%.2f\n",
              static_cast<double>(bytes[0]) / directions,
              static_cast<double>(bytes[1]) / directions,
              static_cast<double>(bytes[1]) / static_cast<double>(bytes[0]));
  return true;
}

// One batch of `batch`'s directions with every part of the uncertainty, its chunks serialised
// into `file` in order. False on an RPC or write error.
bool DumpBatch(v1::Interpolation::Stub& stub, Setup batch, const std::string& file) {
  v1::InterpolateBatchRequest request;
  request.set_session_id(batch.session);
  request.set_method(batch.method);
  request.set_include_uncertainty(true);
  request.set_include_uncertainty_shared(true);
  for (const v1::DirectionQuery& q : batch.directions) *request.add_directions() = q;
  grpc::ClientContext context;
  Authorize(context, batch.token);
  std::ofstream out(file, std::ios::binary);
  auto reader = stub.InterpolateBatch(&context, request);
  v1::InterpolateBatchChunk chunk;
  while (reader->Read(&chunk)) out << chunk.SerializeAsString();
  const grpc::Status st = reader->Finish();
  if (!st.ok()) std::fprintf(stderr, "InterpolateBatch: %s\n", st.error_message().c_str());
  return st.ok() && static_cast<bool>(out);
}

// The timings of every repetition, [0] without and [1] with the uncertainty.
struct Timings {
  const std::vector<double>* unary;
  const std::vector<double>* batched;
  const std::vector<double>* daemon_cpu;
  const std::vector<double>* client_cpu;
};

// The table of medians and their ratios.
void PrintSummary(const Timings& t, int reps, int calls, int directions, bool daemon_measured) {
  const double u0 = Median(t.unary[0]), u1 = Median(t.unary[1]);
  const double b0 = Median(t.batched[0]), b1 = Median(t.batched[1]);
  const std::string header = "median of " + std::to_string(reps) + " reps";
  std::printf("\n%-34s %12s %12s %7s\n", header.c_str(), "without", "with", "ratio");
  std::printf("%-34s %10.1f µs %9.1f µs %7.2f\n",
              ("Interpolate (" + std::to_string(calls) + " calls), per call").c_str(),
              1e6 * u0 / calls, 1e6 * u1 / calls, u1 / u0);
  std::printf("%-34s %11.3f s %10.3f s %7.2f\n",
              ("InterpolateBatch (" + std::to_string(directions) + " dirs)").c_str(), b0, b1,
              b1 / b0);
  if (daemon_measured) {
    const double d0 = Median(t.daemon_cpu[0]), d1 = Median(t.daemon_cpu[1]);
    std::printf("%-34s %11.3f s %10.3f s %7.2f\n", "  its CPU time: the daemon's", d0, d1, d1 / d0);
  }
  const double c0 = Median(t.client_cpu[0]), c1 = Median(t.client_cpu[1]);
  std::printf("%-34s %11.3f s %10.3f s %7.2f\n", "  its CPU time: this client's", c0, c1, c1 / c0);
}

}  // namespace

int main(int argc, char** argv) {
  std::string address, method = "octant";
  Setup s;
  int calls = 2000, directions = 20000, reps = 5;
  double theta_max = 80;
  unsigned seed = 1;
  CLI::App app(
      "bench_interp_uncertainty: Interpolate and InterpolateBatch with and without "
      "uncertainties, same run");
  app.add_option("--address", address, "brdfd's host:port")->required();
  app.add_option("--token", s.token, "bearer token (analyst is enough)");
  app.add_option("--session", s.session, "session to interpolate")->required();
  app.add_option("--method", method, "octant, delaunay or nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}));
  app.add_option("--calls", calls, "Interpolate calls per timing")->check(CLI::Range(1, 1000000));
  app.add_option("--directions", directions, "directions of the batch")
      ->check(CLI::Range(1, 100000));
  app.add_option("--reps", reps, "timed repetitions of each")->check(CLI::Range(1, 100));
  app.add_option("--theta-max", theta_max, "largest θi, θo of the random directions");
  app.add_option("--seed", seed, "seed of the random directions");
  bool all_directions = false;
  app.add_flag("--all-directions", all_directions,
               "time every random direction, also those the method cannot answer");
  app.add_flag("--shared", s.shared, "the batch's answers also carry the shared part");
  app.add_option("--daemon-pid", s.daemon_pid,
                 "brdfd's process id: also report the daemon's CPU time per batch");
  std::string dump;
  app.add_option("--dump", dump, "also write one batch's answers with every part to this file");
  CLI11_PARSE(app, argc, argv);
  s.method = method == "delaunay"  ? v1::INTERPOLATION_METHOD_DELAUNAY
             : method == "nearest" ? v1::INTERPOLATION_METHOD_NEAREST
                                   : v1::INTERPOLATION_METHOD_OCTANT;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);
  auto channel = grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
  auto stub = v1::Interpolation::NewStub(channel);
  const auto wanted = static_cast<std::size_t>(std::max(calls, directions));
  s.directions = all_directions ? RandomDirections(static_cast<int>(wanted), theta_max, seed)
                                : AnsweredDirections(*stub, s, wanted, theta_max, seed);
  if (s.directions.size() < wanted) {
    std::fprintf(stderr, "only %zu directions with an answer (wanted %zu); try --all-directions\n",
                 s.directions.size(), wanted);
    return 1;
  }
  std::vector<v1::DirectionQuery> batch_dirs(s.directions.begin(),
                                             s.directions.begin() + directions);
  Setup batch = s;
  batch.directions = batch_dirs;

  int ok = 0;
  // Warm-up: builds the index and the connection; not timed.
  if (TimeUnary(*stub, s, 50, true, &ok) < 0 || TimeBatch(*stub, batch, true, &ok) < 0) return 1;
  if (!PrintBatchBytes(*stub, batch, directions)) return 1;
  if (!dump.empty() && !DumpBatch(*stub, batch, dump)) return 1;
  std::vector<double> unary[2], batched[2], daemon_cpu[2], client_cpu[2];
  int unary_ok = 0, batch_ok = 0;
  for (int r = 0; r < reps; ++r) {
    for (int k = 0; k < 2; ++k) {
      const bool uncertain = (k + r) % 2 == 1;  // alternate which goes first
      const double tu = TimeUnary(*stub, s, calls, uncertain, &unary_ok);
      CpuSpent cpu;
      const double tb = TimeBatch(*stub, batch, uncertain, &batch_ok, nullptr, nullptr, &cpu);
      if (tu < 0 || tb < 0) return 1;
      unary[uncertain].push_back(tu);
      batched[uncertain].push_back(tb);
      daemon_cpu[uncertain].push_back(cpu.daemon);
      client_cpu[uncertain].push_back(cpu.client);
      std::printf(
          "rep=%d uncertainty=%d interpolate_s=%.4f batch_s=%.4f batch_daemon_cpu_s=%.4f "
          "batch_client_cpu_s=%.4f\n",
          r, uncertain ? 1 : 0, tu, tb, cpu.daemon, cpu.client);
    }
  }
  std::printf("interpolate_ok=%d/%d batch_ok=%d/%d\n", unary_ok, calls, batch_ok, directions);
  PrintSummary(Timings{unary, batched, daemon_cpu, client_cpu}, reps, calls, directions,
               s.daemon_pid > 0);
  return 0;
}
