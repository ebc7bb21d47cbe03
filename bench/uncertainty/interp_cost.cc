// bench_interp_uncertainty: what asking for uncertainties costs Interpolate and InterpolateBatch
// (issue 37: at most 1.5× the time without), against a running brdfd and one session, in the same
// run: each repetition times the same calls with and without include_uncertainty, in alternating
// order, and the medians and their ratio are printed.
//   Interpolate:      --calls sequential unary calls at random directions (one client thread);
//   InterpolateBatch: one call of --directions random directions, every chunk read.
// Directions: θi, θo uniform in [0, --theta-max], φ in [0, 180], from --seed, kept only where the
// method gives a spectrum (an answer that is not OK carries no uncertainty and would only dilute
// the cost; --all-directions keeps them all). The share of OK answers is printed.
//
// Output: "key=value" lines, then a summary table (bench/uncertainty/interp_cost.sh).
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
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
};

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
                 std::vector<v1::DirectionQuery>* answered = nullptr) {
  v1::InterpolateBatchRequest request;
  request.set_session_id(s.session);
  request.set_method(s.method);
  request.set_include_uncertainty(uncertain);
  for (const v1::DirectionQuery& q : s.directions) *request.add_directions() = q;
  grpc::ClientContext context;
  Authorize(context, s.token);
  *ok = 0;
  const auto start = Clock::now();
  auto reader = stub.InterpolateBatch(&context, request);
  v1::InterpolateBatchChunk chunk;
  while (reader->Read(&chunk)) {
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
  return std::chrono::duration<double>(Clock::now() - start).count();
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
  std::vector<double> unary[2], batched[2];
  int unary_ok = 0, batch_ok = 0;
  for (int r = 0; r < reps; ++r) {
    for (int k = 0; k < 2; ++k) {
      const bool uncertain = (k + r) % 2 == 1;  // alternate which goes first
      const double tu = TimeUnary(*stub, s, calls, uncertain, &unary_ok);
      const double tb = TimeBatch(*stub, batch, uncertain, &batch_ok);
      if (tu < 0 || tb < 0) return 1;
      unary[uncertain].push_back(tu);
      batched[uncertain].push_back(tb);
      std::printf("rep=%d uncertainty=%d interpolate_s=%.4f batch_s=%.4f\n", r, uncertain ? 1 : 0,
                  tu, tb);
    }
  }
  const double u0 = Median(unary[0]), u1 = Median(unary[1]);
  const double b0 = Median(batched[0]), b1 = Median(batched[1]);
  std::printf("interpolate_ok=%d/%d batch_ok=%d/%d\n", unary_ok, calls, batch_ok, directions);
  const std::string header = "median of " + std::to_string(reps) + " reps";
  std::printf("\n%-34s %12s %12s %7s\n", header.c_str(), "without", "with", "ratio");
  std::printf("%-34s %10.1f µs %9.1f µs %7.2f\n",
              ("Interpolate (" + std::to_string(calls) + " calls), per call").c_str(),
              1e6 * u0 / calls, 1e6 * u1 / calls, u1 / u0);
  std::printf("%-34s %11.3f s %10.3f s %7.2f\n",
              ("InterpolateBatch (" + std::to_string(directions) + " dirs)").c_str(), b0, b1,
              b1 / b0);
  return 0;
}
