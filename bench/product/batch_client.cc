// bench_interpolate_batch: InterpolateBatch end to end against a running brdfd: reads directions
// (θi, θo, φ per line, comma-separated, a header line first) from a CSV, sends them in one
// request, receives every chunk, and prints the wall time from the call to the last chunk and
// the answers' statuses; --reps repeats the call (the first one also builds the session's index
// in brdfd unless it is built already: run a warm-up call, --warmup). With --spectra FILE the
// last repetition's spectra are written as raw little-endian doubles, n × bands (NaN where the
// status is not ok), for a comparison with scipy's answers.
//
// Output: one "key=value" line per repetition (bench/product/run.sh parses them).
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"

namespace {

using Clock = std::chrono::steady_clock;

std::vector<double> ReadDirections(const std::string& path) {
  std::ifstream in(path);
  std::vector<double> out;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string v;
    while (std::getline(fields, v, ',')) out.push_back(std::stod(v));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string address, token, session, directions_path, spectra_path, method = "octant";
  int reps = 3;
  int warmup = 1;
  CLI::App app("bench_interpolate_batch: InterpolateBatch end to end against a running brdfd");
  app.add_option("--address", address, "brdfd's host:port")->required();
  app.add_option("--token", token, "bearer token (analyst is enough)");
  app.add_option("--session", session, "session to interpolate")->required();
  app.add_option("--directions", directions_path, "CSV of θi,θo,φ with a header")->required();
  app.add_option("--method", method, "octant, delaunay or nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}));
  app.add_option("--reps", reps, "timed calls")->check(CLI::Range(1, 100));
  app.add_option("--warmup", warmup, "untimed calls first")->check(CLI::Range(0, 100));
  app.add_option("--spectra", spectra_path, "write the last call's spectra here (raw doubles)");
  CLI11_PARSE(app, argc, argv);

  const std::vector<double> dirs = ReadDirections(directions_path);
  brdf::v1::InterpolateBatchRequest request;
  request.set_session_id(session);
  request.set_method(method == "delaunay"  ? brdf::v1::INTERPOLATION_METHOD_DELAUNAY
                     : method == "nearest" ? brdf::v1::INTERPOLATION_METHOD_NEAREST
                                           : brdf::v1::INTERPOLATION_METHOD_OCTANT);
  for (std::size_t i = 0; i + 2 < dirs.size(); i += 3) {
    brdf::v1::IsoDirection* iso = request.add_directions()->mutable_iso();
    iso->set_theta_i(dirs[i]);
    iso->set_theta_o(dirs[i + 1]);
    iso->set_phi(dirs[i + 2]);
  }
  const int n = request.directions_size();
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);
  args.SetMaxSendMessageSize(-1);
  auto stub = brdf::v1::Interpolation::NewStub(
      grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args));

  std::vector<double> spectra;
  for (int r = 0; r < warmup + reps; ++r) {
    grpc::ClientContext context;
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(10));
    const Clock::time_point start = Clock::now();
    auto reader = stub->InterpolateBatch(&context, request);
    brdf::v1::InterpolateBatchChunk chunk;
    long results = 0, ok = 0;
    std::size_t bands = 0;
    const bool keep = r + 1 == warmup + reps && !spectra_path.empty();
    while (reader->Read(&chunk)) {
      for (const brdf::v1::InterpolationResult& res : chunk.results()) {
        ++results;
        const bool is_ok = res.status() == brdf::v1::INTERPOLATION_STATUS_OK;
        ok += is_ok;
        if (!keep) continue;
        if (bands == 0 && is_ok) {
          bands = static_cast<std::size_t>(res.spectrum_size());
          spectra.assign(static_cast<std::size_t>(n) * bands,
                         std::numeric_limits<double>::quiet_NaN());
        }
        if (is_ok && bands > 0) {
          const std::size_t i = static_cast<std::size_t>(results - 1);
          for (std::size_t b = 0; b < bands; ++b) spectra[i * bands + b] = res.spectrum(int(b));
        }
      }
    }
    const grpc::Status st = reader->Finish();
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    if (!st.ok()) {
      std::fprintf(stderr, "bench_interpolate_batch: %s\n", st.error_message().c_str());
      return 1;
    }
    if (r < warmup) continue;
    std::printf("batch method=%s directions=%d results=%ld ok=%ld wall_s=%.4f\n", method.c_str(), n,
                results, ok, wall);
    std::fflush(stdout);
    if (keep) {
      std::ofstream out(spectra_path, std::ios::binary);
      out.write(reinterpret_cast<const char*>(spectra.data()),
                static_cast<std::streamsize>(spectra.size() * sizeof(double)));
    }
  }
  return 0;
}
