// The grid export's interpolation without brdfd, gRPC or brdfctl (issue 41, bench/README.md):
// the octant method over the cell centres of a regular (θi, θo, φ) grid, from a session's
// samples given as two binary files. Two modes:
//   search  SpectraAt on one thread, one θi slice per batch (core/export/grid/regular_grid.cc
//           batches a 1° × 1° × 2° grid that way): the time in SpectraAt and a checksum of the
//           statuses and spectra (equal checksums: the same answers, bit for bit);
//   random  SpectraAt of 100,000 uniform random directions (θi, θo ∈ [0, 90), φ ∈ [0, 180)) in
//           one call, as bench_interpolate_batch's (not the same numbers): the other batch shape;
//   write   ResampleOnGrid on every core into an .npy file with NpyGridWriter: what an export
//           that brdfd wrote to the file itself would cost (no fallback for the cells the octant
//           method leaves empty: they hold NaN).
//
// Usage: bench_grid_search search|random|write POINTS.f64 VALUES.f64 BANDS [OUT.npy] [REPS]
//   POINTS.f64: n × 3 doubles (θi, θo, φ in degrees, as brdfd reduces a reading); VALUES.f64:
//   n × BANDS doubles (numpy's tofile of a readings CSV's BRDF, bench/README.md says how).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/spectrum_source.h"
#include "core/export/grid/npy_writer.h"
#include "core/export/grid/regular_grid.h"
#include "core/interp/octant/octant.h"

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::vector<double> ReadDoubles(const char* path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto size = static_cast<std::size_t>(in.tellg());
  std::vector<double> v(size / sizeof(double));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * 8));
  return v;
}

std::uint64_t Mix(std::uint64_t h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::size_t i = 0;
  for (; i + 8 <= bytes; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = (h ^ w) * 1099511628211ull;
  }
  for (; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// SpectraAt slice by slice on this thread; prints the time and the checksum.
void Search(const brdf::interp::OctantInterpolator& interp, const brdf::exports::RegularGrid& grid,
            int bands) {
  const std::size_t slice = grid.theta_o.count * grid.phi.count;
  std::vector<double> q(3 * slice);
  std::vector<brdf::interp::InterpStatus> st(slice);
  std::vector<double> out(slice * static_cast<std::size_t>(bands));
  std::uint64_t h = 1469598103934665603ull;
  std::size_t ok = 0;
  double s = 0.0;
  for (std::size_t i = 0; i < grid.theta_i.count; ++i) {
    for (std::size_t c = 0; c < slice; ++c) {
      q[3 * c] = grid.theta_i.at(i);
      q[3 * c + 1] = grid.theta_o.at(c / grid.phi.count);
      q[3 * c + 2] = grid.phi.at(c % grid.phi.count);
    }
    const auto t0 = Clock::now();
    interp.SpectraAt(q, st, out);
    s += Since(t0);
    for (auto status : st) ok += status == brdf::interp::InterpStatus::kOk;
    h = Mix(h, st.data(), st.size() * sizeof(st[0]));
    h = Mix(h, out.data(), out.size() * sizeof(double));
  }
  std::printf("search_s=%.3f cells=%zu ok=%zu checksum=%016llx\n", s, grid.cells(), ok,
              static_cast<unsigned long long>(h));
}

// SpectraAt of 100,000 random directions (a fixed seed) in one call; prints the time and checksum.
void Random(const brdf::interp::OctantInterpolator& interp, int bands) {
  constexpr std::size_t kQueries = 100000;
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> q(3 * kQueries);
  for (std::size_t i = 0; i < kQueries; ++i) {
    q[3 * i] = 90.0 * u(rng);
    q[3 * i + 1] = 90.0 * u(rng);
    q[3 * i + 2] = 180.0 * u(rng);
  }
  std::vector<brdf::interp::InterpStatus> st(kQueries);
  std::vector<double> out(kQueries * static_cast<std::size_t>(bands));
  const auto t0 = Clock::now();
  interp.SpectraAt(q, st, out);
  const double s = Since(t0);
  std::uint64_t h = Mix(1469598103934665603ull, st.data(), st.size() * sizeof(st[0]));
  h = Mix(h, out.data(), out.size() * sizeof(double));
  std::printf("random_s=%.3f queries=%zu checksum=%016llx\n", s, kQueries,
              static_cast<unsigned long long>(h));
}

// ResampleOnGrid on every core into `path`; prints the time (the file closed).
int Write(const brdf::interp::OctantInterpolator& interp, const brdf::exports::RegularGrid& grid,
          int bands, const char* path) {
  const auto t0 = Clock::now();
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  brdf::exports::NpyGridWriter npy(file);
  const brdf::WavelengthGrid wavelengths{380.0, 400.0 / (bands - 1),
                                         static_cast<std::size_t>(bands)};
  brdf::exports::RunControl control;
  control.threads = 0;
  const auto ctx = brdf::CallContext::WithTimeout(std::chrono::minutes(10));
  auto report = brdf::exports::ResampleOnGrid(brdf::exports::InterpolatorSource(interp), grid,
                                              wavelengths, control, ctx, npy);
  file.close();
  if (!report.ok() || !file) {
    std::fprintf(stderr, "write failed: %s\n", report.status().ToString().c_str());
    return 1;
  }
  std::printf("write_s=%.3f %s\n", Since(t0), report->Summary().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr,
                 "usage: %s search|random|write POINTS.f64 VALUES.f64 BANDS [OUT.npy] [REPS]\n",
                 argv[0]);
    return 2;
  }
  const std::string mode = argv[1];
  const int bands = std::atoi(argv[4]);
  const bool write = mode == "write";
  if (write && argc < 6) return 2;
  const int reps = argc > (write ? 6 : 5) ? std::atoi(argv[write ? 6 : 5]) : 3;
  const std::vector<double> points = ReadDoubles(argv[2]);
  const std::vector<double> values = ReadDoubles(argv[3]);
  auto samples = std::make_shared<brdf::interp::SampleSet>(3, bands);
  for (std::size_t i = 0; i < points.size() / 3; ++i) {
    const auto status =
        samples->Add(static_cast<std::int64_t>(i), std::span(points.data() + 3 * i, 3),
                     std::span(values.data() + i * static_cast<std::size_t>(bands),
                               static_cast<std::size_t>(bands)));
    if (!status.ok()) {
      std::fprintf(stderr, "sample %zu: %s\n", i, status.ToString().c_str());
      return 1;
    }
  }
  const auto t0 = Clock::now();
  auto made = brdf::interp::OctantInterpolator::Create(samples);
  if (!made.ok()) return 1;
  std::printf("build_s=%.3f samples=%zu\n", Since(t0), samples->size());
  auto grid = brdf::exports::MakeRegularGrid(1, 1, 2, brdf::exports::GridPlacement::kCellCentres);
  if (!grid.ok()) return 1;
  for (int r = 0; r < reps; ++r) {
    if (mode == "random") {
      Random(**made, bands);
    } else if (!write) {
      Search(**made, *grid, bands);
    } else if (Write(**made, *grid, bands, argv[5]) != 0) {
      return 1;
    }
  }
  return 0;
}
