// bench_storage: the storage side of the daemon's figures, through storage/'s own API (the same
// calls the executor makes).
//
//   ingest --db FILE [--readings N] [--seconds S]
//     readings ingested per second: CompleteStepWithReading, one transaction per reading (reading
//     and done mark), synchronous=FULL (storage/sqlite.cc), 101-band PR-650 spectra, on the disk
//     FILE is on. Stops after N readings or S seconds, whichever first.
//   create --db FILE --readings N
//     a COMPLETED isotropic session of N sample readings (plus its white reference and dark) at
//     random directions, as brdfd would have stored it: what the memory figure loads into brdfd.
//     Put FILE on a tmpfs (the one-fsync-per-reading cost is what `ingest` measures, not this).
//
// Output: one "key=value" line (bench/daemon/run.sh parses it).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/wavelength_grid.h"
#include "storage/session_store.h"

namespace {

using namespace brdf;

// A session of `samples` sample steps after a reference and a dark; returns its id.
Result<std::int64_t> NewSessionWith(storage::SessionStore& store, int samples) {
  storage::NewSession s;
  s.name = "bench: " + std::to_string(samples) + " readings";
  s.plan_kind = "pose_list";
  s.plan_json = R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]}})";
  s.created_by_role = "operator";
  s.white_reflectance = 0.99;
  std::vector<storage::StepRecord> steps;
  auto add = [&](storage::StepKind kind) {
    storage::StepRecord r;
    r.step_index = static_cast<int>(steps.size());
    r.kind = kind;
    steps.push_back(r);
  };
  add(storage::StepKind::kReference);
  add(storage::StepKind::kDark);
  for (int i = 0; i < samples; ++i) add(storage::StepKind::kSample);
  Result<std::int64_t> id = store.CreateSession(s, steps);
  if (!id.ok()) return id;
  BRDF_RETURN_IF_ERROR(store.SetSessionState(*id, SessionState::kRunning, "bench"));
  return id;
}

// Writes the reference, the dark and `samples` sample readings at random iso directions
// (θi, θo in [0, 80], φ in [0, 180]); calls `tick` after each sample (false: stop).
template <typename Tick>
Result<int> Fill(storage::SessionStore& store, std::int64_t session, int samples, Tick tick) {
  const WavelengthGrid grid = WavelengthGrid::Pr650();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> theta(0, 80);
  std::uniform_real_distribution<double> phi(0, 180);
  std::uniform_real_distribution<double> level(0.01, 0.2);
  auto reading = [&](storage::ReadingKind kind, const Directions& d, double value) {
    storage::ReadingRecord r;
    r.kind = kind;
    r.directions = d;
    r.grid = grid;
    r.spectrum.resize(static_cast<std::size_t>(grid.count));
    for (std::size_t b = 0; b < r.spectrum.size(); ++b) {
      r.spectrum[b] = value * (1 + 0.002 * static_cast<double>(b));
    }
    r.integration_ms = 100;
    return r;
  };
  Result<std::int64_t> reference = store.CompleteStepWithReading(
      session, 0, reading(storage::ReadingKind::kReference, {10, 0, 10, 180}, 1.0));
  if (!reference.ok()) return reference.status();
  Result<std::int64_t> dark =
      store.CompleteStepWithReading(session, 1, reading(storage::ReadingKind::kDark, {}, 0.001));
  if (!dark.ok()) return dark.status();
  int written = 0;
  for (int i = 0; i < samples; ++i) {
    storage::ReadingRecord r =
        reading(storage::ReadingKind::kSample, {theta(rng), 0, theta(rng), phi(rng)}, level(rng));
    r.reference_reading_id = *reference;
    r.dark_reading_id = *dark;
    Result<std::int64_t> id = store.CompleteStepWithReading(session, 2 + i, r);
    if (!id.ok()) return id.status();
    ++written;
    if (!tick()) break;
  }
  return written;
}

}  // namespace

int main(int argc, char** argv) {
  std::string db;
  int readings = 50000;
  double seconds = 5;
  CLI::App app(
      "bench_storage: SQLite ingest rate, and sessions of N readings for the memory figure");
  app.require_subcommand(1);
  CLI::App* ingest = app.add_subcommand("ingest", "readings per second, one transaction each");
  ingest->add_option("--db", db, "database file (created)")->required();
  ingest->add_option("--readings", readings, "at most this many readings")
      ->check(CLI::Range(1, 10000000));
  ingest->add_option("--seconds", seconds, "at most this long")->check(CLI::Range(0.1, 600.0));
  CLI::App* create = app.add_subcommand("create", "a completed session of N sample readings");
  create->add_option("--db", db, "database file (created)")->required();
  create->add_option("--readings", readings, "sample readings")->check(CLI::Range(1, 10000000));
  CLI11_PARSE(app, argc, argv);

  std::filesystem::remove(db);
  Result<std::unique_ptr<storage::SessionStore>> store = storage::SessionStore::Open(db);
  if (!store.ok()) {
    std::fprintf(stderr, "bench_storage: %s\n", store.status().ToString().c_str());
    return 1;
  }
  Result<std::int64_t> session = NewSessionWith(**store, readings);
  if (!session.ok()) {
    std::fprintf(stderr, "bench_storage: %s\n", session.status().ToString().c_str());
    return 1;
  }
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const Clock::time_point until =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  const bool timed = ingest->parsed();
  Result<int> written =
      Fill(**store, *session, readings, [&] { return !timed || Clock::now() < until; });
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  if (!written.ok()) {
    std::fprintf(stderr, "bench_storage: %s\n", written.status().ToString().c_str());
    return 1;
  }
  if (timed) {
    std::printf("ingest readings=%d seconds=%.2f per_s=%.0f\n", *written, elapsed,
                *written / elapsed);
    return 0;
  }
  if (Status st = (*store)->SetSessionState(*session, SessionState::kCompleted, "bench");
      !st.ok()) {
    std::fprintf(stderr, "bench_storage: %s\n", st.ToString().c_str());
    return 1;
  }
  std::printf("create session=%lld readings=%d seconds=%.2f bytes=%lld\n",
              static_cast<long long>(*session), *written, elapsed,
              static_cast<long long>(std::filesystem::file_size(db)));
  return 0;
}
