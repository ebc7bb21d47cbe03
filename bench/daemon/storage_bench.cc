// bench_storage: the storage side of the daemon's figures, through storage/'s own API (the same
// calls the executor makes).
//
//   ingest --db FILE [--readings N] [--seconds S]
//     readings ingested per second: CompleteStepWithReading, one transaction per reading (reading
//     and done mark), synchronous=FULL (storage/sqlite.cc), 101-band PR-650 spectra, on the disk
//     FILE is on. Stops after N readings or S seconds, whichever first.
//   create --db FILE --readings N [--bands 101|201|401] [--budgets]
//     a COMPLETED isotropic session of N sample readings (plus its white reference and dark) as
//     brdfd would have stored it: what the memory figure loads into brdfd and the web explorer's
//     bench (web/bench/explorer_50k.mjs) shows. Put FILE on a tmpfs (the one-fsync-per-reading
//     cost is what `ingest` measures, not this). --budgets: each sample reading also stores its
//     uncertainty budget (docs/uncertainty.md; the meter's default noise model, white standard
//     0.99 ± 0.0058, no lamp drift or pose term: both named not estimated), for the cost of
//     interpolated values' and exports' uncertainties (bench/uncertainty/).
//
// The readings are at the rig's poses (RigPoses: the paper's sample-rotation grid, passes after
// the first jittered), their directions from the pose by the rig's kinematics, their radiance
// that of a paint-like sample (core/analytic_brdf.h) under the reference's lamp.
//
// Output: one "key=value" line (bench/daemon/run.sh parses it).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/analytic_brdf.h"
#include "core/geometry.h"
#include "core/uncertainty/budget.h"
#include "core/wavelength_grid.h"
#include "storage/session_store.h"

namespace {

using namespace brdf;

// The session's white standard (Session.white_reflectance), ρw in the readings' derivation.
constexpr double kWhiteReflectance = 0.99;

// The white standard's standard uncertainty (a rectangular ±1 %).
constexpr double kWhiteReflectanceU = 0.0058;

// Sample reading `r`'s budget against its reference and dark (BudgetInputs' defaults otherwise).
Result<uncertainty::ReadingBudget> BudgetOf(std::int64_t session, const storage::ReadingRecord& r,
                                            const storage::ReadingRecord& reference,
                                            std::int64_t reference_id,
                                            const storage::ReadingRecord& dark,
                                            std::int64_t dark_id) {
  uncertainty::BudgetInputs in;
  in.session_id = session;
  in.grid = r.grid;
  in.sample = {0, r.spectrum, r.integration_ms, 1};
  in.reference = {reference_id, reference.spectrum, reference.integration_ms, 1};
  in.dark = uncertainty::MeasuredSignal{dark_id, dark.spectrum, dark.integration_ms, 1};
  in.white_reflectance = {kWhiteReflectance};
  in.white_reflectance_u = {kWhiteReflectanceU};
  in.theta_i_deg = r.directions.theta_i;
  in.theta_r_deg = reference.directions.theta_i;
  return uncertainty::EstimateReadingBudget(in);
}

// A session of `samples` sample steps after a reference and a dark; returns its id.
Result<std::int64_t> NewSessionWith(storage::SessionStore& store, int samples) {
  storage::NewSession s;
  s.name = "bench: " + std::to_string(samples) + " readings";
  s.plan_kind = "pose_list";
  s.plan_json = R"({"poseList": {"poses": [{"alpha": 0, "beta": 0, "delta": 0}]}})";
  s.created_by_role = "operator";
  s.white_reflectance = kWhiteReflectance;
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
  BRDF_ASSIGN_OR_RETURN(std::int64_t id, store.CreateSession(s, steps));
  BRDF_RETURN_IF_ERROR(store.SetSessionState(id, SessionState::kRunning, "bench"));
  return id;
}

// The poses of a long session on the rig: the paper's sample-rotation grid (GridSpec's defaults,
// 2,320 poses over α 0…70°, δ 0…146.25°, β every 5° where lamp and detector are above the
// surface), pass after pass; every pass after the first is jittered by up to ±2° in α, β and δ
// (within the stages' travel; a jittered pose whose lamp or detector would leave the surface is
// taken as on the grid), so N readings fill the hemisphere in (θi, θo, φ) rather than repeat
// 2,320 points.
class RigPoses {
 public:
  static Result<RigPoses> Make() {
    BRDF_ASSIGN_OR_RETURN(std::vector<Pose> grid, ExpandSampleRotationGrid(GridSpec{}));
    return RigPoses(std::move(grid));
  }
  // The pose of the i-th sample reading, with its directions.
  std::pair<Pose, Directions> Next(std::size_t i) {
    const Pose on_grid = grid_[i % grid_.size()];
    if (i < grid_.size()) return {on_grid, PoseToDirections(on_grid)};
    Pose jittered = on_grid;
    // α and δ stay within the rig's travel (PoseLimits' defaults).
    const PoseLimits limits;
    jittered.alpha =
        std::clamp(on_grid.alpha + jitter_(rng_), limits.alpha_min_deg, limits.alpha_max_deg);
    jittered.beta += jitter_(rng_);
    jittered.delta =
        std::clamp(on_grid.delta + jitter_(rng_), limits.delta_min_deg, limits.delta_max_deg);
    const Directions d = PoseToDirections(jittered);
    if (IsValid(d, GridSpec{}.theta_max_deg)) return {jittered, d};
    return {on_grid, PoseToDirections(on_grid)};
  }

 private:
  explicit RigPoses(std::vector<Pose> grid) : grid_(std::move(grid)) {}
  std::vector<Pose> grid_;
  std::mt19937_64 rng_{7};
  std::uniform_real_distribution<double> jitter_{-2, 2};
};

// Writes the reference, the dark and `samples` sample readings at the rig's poses (RigPoses);
// calls `tick` after each sample (false: stop).
template <typename Tick>
Result<int> Fill(storage::SessionStore& store, std::int64_t session, int samples,
                 const WavelengthGrid& grid, bool budgets, Tick tick) {
  BRDF_ASSIGN_OR_RETURN(RigPoses poses, RigPoses::Make());
  // The white reference's spectrum I0 (lamp and detector 10° off the normal), the dark D; a
  // sample's radiance is D + (I0 − D)·f·π/ρw·cos θi/cos θi,ref for the paint's BRDF f, i.e. what
  // the daemon's derivation (core/readings/derive.h) turns back into f.
  const Directions reference_at{10, 0, 10, 180};
  auto lamp = [&](std::size_t b) { return 1 + 0.002 * static_cast<double>(b); };
  const double dark_level = 0.001;
  const AnalyticBrdf paint = AnalyticBrdf::PaintLike();
  constexpr double kPi = std::numbers::pi;
  auto reading = [&](storage::ReadingKind kind, const Pose& pose, const Directions& d) {
    storage::ReadingRecord r;
    r.kind = kind;
    r.pose = pose;
    r.directions = d;
    r.grid = grid;
    r.spectrum.resize(static_cast<std::size_t>(grid.count));
    const double cos_ratio =
        std::cos(d.theta_i * kPi / 180) / std::cos(reference_at.theta_i * kPi / 180);
    for (std::size_t b = 0; b < r.spectrum.size(); ++b) {
      const double dark = dark_level * lamp(b);
      switch (kind) {
        case storage::ReadingKind::kReference:
          r.spectrum[b] = lamp(b);
          break;
        case storage::ReadingKind::kDark:
          r.spectrum[b] = dark;
          break;
        default:
          r.spectrum[b] = dark + (lamp(b) - dark) * paint.Evaluate(d, grid.at(b)) * kPi /
                                     kWhiteReflectance * cos_ratio;
      }
    }
    r.integration_ms = 100;
    return r;
  };
  const storage::ReadingRecord reference_reading =
      reading(storage::ReadingKind::kReference, {}, reference_at);
  const storage::ReadingRecord dark_reading = reading(storage::ReadingKind::kDark, {}, {});
  BRDF_ASSIGN_OR_RETURN(std::int64_t reference,
                        store.CompleteStepWithReading(session, 0, reference_reading));
  BRDF_ASSIGN_OR_RETURN(std::int64_t dark, store.CompleteStepWithReading(session, 1, dark_reading));
  int written = 0;
  for (int i = 0; i < samples; ++i) {
    const auto [pose, directions] = poses.Next(static_cast<std::size_t>(i));
    storage::ReadingRecord r = reading(storage::ReadingKind::kSample, pose, directions);
    r.reference_reading_id = reference;
    r.dark_reading_id = dark;
    if (budgets) {
      BRDF_ASSIGN_OR_RETURN(r.uncertainty,
                            BudgetOf(session, r, reference_reading, reference, dark_reading, dark));
    }
    BRDF_RETURN_IF_ERROR(store.CompleteStepWithReading(session, 2 + i, r).status());
    ++written;
    if (!tick()) break;
  }
  return written;
}

}  // namespace

int main(int argc, char** argv) {
  std::string db;
  int readings = 50000;
  int bands = 101;
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
  create
      ->add_option("--bands", bands,
                   "bands from 380 to 780 nm: 101 (PR-650, 4 nm), 201 (PR-670, 2 nm) or 401 "
                   "(CS-2000, 1 nm)")
      ->check(CLI::IsMember({101, 201, 401}));
  bool budgets = false;
  create->add_flag("--budgets", budgets, "store each sample reading's uncertainty budget");
  CLI11_PARSE(app, argc, argv);
  const WavelengthGrid grid{380, 400.0 / (bands - 1), static_cast<std::size_t>(bands)};

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
  Result<int> written = Fill(**store, *session, readings, grid, budgets,
                             [&] { return !timed || Clock::now() < until; });
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
