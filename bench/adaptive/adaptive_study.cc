// bench_adaptive_study: the adaptive planner's loop without a rig (issue 38, docs/adaptive.md
// "The offline study"). For each material file (brdf-sim's material code) and seed: the adaptive
// plan's seed design, then rounds chosen by ChooseRound with the interpolated uncertainty model
// (core/adaptive/interpolated_model.h), each reading the material's true scalar BRDF (the mean
// over 400–700 nm) at the pose's directions times (1 + its stated relative u · a normal draw).
// Stops at 10, 20, 30 and 50 % of the paper grid's sample readings and judges each stage, and the
// paper grid itself measured the same way, by the octant method (JudgeOptions) against the truth:
//   err     relative RMS of the cosine-weighted BRDF f · cos θi · cos θo at --directions random
//           direction pairs with θi, θo ≤ 80° (--judge-theta-max; the daemon benchmark's), within
//           the plan's region's lower limits (lamp and detector each uniform in solid angle);
//   spec    the same along the specular ridge (θi = θo, φ = 180°), 400 points;
//   retro   the same along the retro-reflection ridge (θi = θo, φ = 0°).
// A direction the octant method cannot answer takes its nearest reading's value (counted: fb %).
// Rig time is the plan timing model's (prompts at the rig's 30 s each) over the session's steps, as
// the daemon sums them: the seed's expansion, then each round expanded after it as the engine
// stores it (round_steps.h: relocations, and references by the plan's policies, by detector
// position, count or time); the grid's expansion. --detector-arm: a motorized detector arm (the
// daemon benchmark's brdf-sim rig) instead of the default manual detector.
//
//   bench_adaptive_study --material deploy/materials/paint.toml --seeds 1 2 3
//   bench_adaptive_study --material deploy/materials/paint.toml --seeds 1 --stages "10 20"
//   bench_adaptive_study --timing      (Map on 2,000 readings, a round of 24 over 5,000 candidates)
//   … --breakdown        each stage's squared error by the half-vector angle θh and by the angle ψ
//                        between lamp and detector, the unanswered and the grazing directions'
//                        share, and where the readings are (the same bins)
//   … --grid bench/adaptive/paper-grid-fifth.json   against the paper grid with β every 25°: its
//                        loops at 464 readings, a fifth (the goal's "at equal readings")
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/adaptive/adaptive_spec.h"
#include "core/adaptive/candidates.h"
#include "core/adaptive/interpolated_model.h"
#include "core/adaptive/round_chooser.h"
#include "core/adaptive/round_cost.h"
#include "core/adaptive/round_steps.h"
#include "core/adaptive/seed_design.h"
#include "core/geometry.h"
#include "core/interp/half_difference.h"
#include "core/interp/interpolator.h"
#include "core/plan/analyze_plan.h"
#include "core/plan/expand_steps.h"
#include "core/plan/plan_json.h"
#include "tools/brdf-sim/optics/material.h"

namespace {

using namespace brdf;
using adaptive::ReadingSoFar;

double Rad(double deg) {
  return deg * std::numbers::pi / 180;
}

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "bench_adaptive_study: %s\n", what.c_str());
  std::exit(2);
}

v1::Plan LoadPlan(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail("cannot open " + path);
  std::stringstream text;
  text << in.rdbuf();
  Result<v1::Plan> plan = plan::ParsePlanJson(text.str());
  if (!plan.ok()) Fail(path + ": " + plan.status().message());
  return *plan;
}

// The material's scalar BRDF as the engine summarises a reading: the mean over the PR-650's bands
// from 400 to 700 nm.
class Truth {
 public:
  explicit Truth(material::Material m) : material_(std::move(m)) {
    const WavelengthGrid grid = WavelengthGrid::Pr650();
    for (std::size_t i = 0; i < grid.count; ++i) {
      if (grid.at(i) >= 400 - 1e-9 && grid.at(i) <= 700 + 1e-9) nm_.push_back(grid.at(i));
    }
  }
  double operator()(const Directions& d) const {
    double sum = 0;
    for (double nm : nm_) sum += material_.Evaluate(d, nm);
    return sum / static_cast<double>(nm_.size());
  }
  const std::string& name() const { return material_.name(); }

 private:
  material::Material material_;
  std::vector<double> nm_;
};

// A simulated reading: the truth × (1 + u · N(0, 1)), u its stated relative uncertainty.
ReadingSoFar Measure(const Truth& truth, const Pose& model, const Directions& d, double u,
                     std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return {model, d, truth(d) * (1 + u * normal(rng)), u};
}

// The sample steps of an expanded plan: model angles and directions.
struct Expanded {
  std::vector<plan::Step> steps;
  std::vector<Pose> poses;
  std::vector<Directions> directions;
  double seconds = 0;
  int prompts = 0;
};

Expanded Expand(const v1::Plan& plan, const plan::RigDescription& rig) {
  const plan::PlanAnalysis analysis = plan::AnalyzePlan(plan, rig);
  if (!analysis.valid()) Fail("plan not valid: " + analysis.problems.front().message);
  Expanded out;
  out.steps = analysis.steps;
  for (const plan::Step& s : analysis.steps) {
    if (s.kind != v1::STEP_KIND_SAMPLE || !s.target.has_value()) continue;
    out.poses.push_back(ToModelAngles(s.pose, rig.convention));
    out.directions.push_back(*s.target);
  }
  out.seconds = analysis.summary.estimated_duration_s;
  out.prompts = analysis.summary.operator_interventions;
  return out;
}

// Where the error is judged: random direction pairs in the region and the two ridges.
struct Judging {
  std::vector<Directions> random, specular, retro;
};

Directions RandomPair(std::mt19937_64& rng, double theta_max) {
  std::uniform_real_distribution<double> cos_t(std::cos(Rad(theta_max)), 1), phi(-180, 180);
  const double ti = std::acos(cos_t(rng)) * 180 / std::numbers::pi;
  const double to = std::acos(cos_t(rng)) * 180 / std::numbers::pi;
  return {ti, phi(rng), to, phi(rng)};
}

Judging JudgingDirections(adaptive::Region region, int count, double theta_max) {
  Judging out;
  std::mt19937_64 rng(20261206);
  if (theta_max > 0) region.theta_i_max_deg = region.theta_o_max_deg = theta_max;
  const double max = std::min(region.theta_i_max_deg, region.theta_o_max_deg);
  while (static_cast<int>(out.random.size()) < count) {
    const Directions d = RandomPair(rng, max);
    if (adaptive::RegionContains(region, d)) out.random.push_back(d);
  }
  for (int i = 0; i < 400; ++i) {
    const double t = max * (i + 0.5) / 400;
    out.specular.push_back(CanonicalDirections({t, t, 180}));
    out.retro.push_back(CanonicalDirections({t, t, 0}));
  }
  return out;
}

// Where the error is (--breakdown): each random direction's squared cosine-weighted error, as a
// share of the sum of the squared cosine-weighted truth (so the shares add up to err²), in bins of
// the half-vector angle θh (0: the mirror direction, where a specular lobe peaks) and of the angle
// ψ = 2 θd between lamp and detector (0: retro-reflection; on the rig ψ is the detector position
// δ, the same for every reading at that δ).
inline constexpr double kThetaHBins[] = {0, 5, 10, 15, 25, 90.001};
inline constexpr double kPsiBins[] = {0, 5.625, 11.25, 16.875, 22.5, 33.75, 180.001};
constexpr int kThetaHCount = 5;
constexpr int kPsiCount = 6;

struct Breakdown {
  double by_theta_h[kThetaHCount] = {};
  double by_psi[kPsiCount] = {};
  double fallback = 0;  // the directions the octant method did not answer (its nearest reading)
  double grazing = 0;   // the directions with θi or θo above 75°
};

int BinOf(double x, const double* edges, int count) {
  for (int i = 0; i < count; ++i) {
    if (x < edges[i + 1]) return i;
  }
  return count - 1;
}

struct Error {
  double random = 0, specular = 0, retro = 0, fallback = 0;
  Breakdown breakdown;
};

// The octant method's value at `d`, or the nearest reading's where it has none.
class Judge {
 public:
  explicit Judge(const std::vector<ReadingSoFar>& readings)
      : samples_(std::make_shared<interp::SampleSet>(3, 1)) {
    for (const ReadingSoFar& r : readings) {
      const IsoDirection iso = ToIsotropic(r.directions);
      const double c[3] = {iso.theta_i, iso.theta_o, iso.phi};
      const double v[1] = {r.brdf};
      if (!samples_->Add(static_cast<std::int64_t>(samples_->size()), c, v).ok()) Fail("add");
    }
    auto index =
        interp::MakeInterpolator(interp::Method::kOctant, samples_, adaptive::JudgeOptions());
    if (!index.ok()) Fail("octant index: " + index.status().message());
    index_ = std::move(*index);
  }
  double operator()(const Directions& d, bool* fallback) const {
    const IsoDirection iso = ToIsotropic(d);
    const double q[3] = {iso.theta_i, iso.theta_o, iso.phi};
    double value[1] = {0};
    *fallback = index_->SpectrumAt(q, value) != interp::InterpStatus::kOk;
    return *fallback ? Nearest(q) : value[0];
  }

 private:
  double Nearest(const double* q) const {
    double best = INFINITY, value = 0;
    for (std::size_t i = 0; i < samples_->size(); ++i) {
      const auto c = samples_->coords(i);
      const double d = std::hypot(c[0] - q[0], c[1] - q[1], c[2] - q[2]);
      if (d < best) best = d, value = samples_->spectrum(i)[0];
    }
    return value;
  }
  std::shared_ptr<interp::SampleSet> samples_;
  std::unique_ptr<interp::Interpolator> index_;
};

// Relative RMS of f · cos θi · cos θo over `at`; counts fallbacks; the breakdown when asked.
double RelativeRms(const Judge& judge, const Truth& truth, const std::vector<Directions>& at,
                   int* fallbacks, Breakdown* breakdown = nullptr) {
  double err2 = 0, ref2 = 0;
  Breakdown b;
  for (const Directions& d : at) {
    bool fb = false;
    const double w = std::cos(Rad(d.theta_i)) * std::cos(Rad(d.theta_o));
    const double e = (judge(d, &fb) - truth(d)) * w;
    const double t = truth(d) * w;
    err2 += e * e;
    ref2 += t * t;
    *fallbacks += fb ? 1 : 0;
    if (breakdown == nullptr) continue;
    const interp::HalfDiffAngles hd = interp::ToHalfDifference(ToIsotropic(d));
    b.by_theta_h[BinOf(hd.theta_h, kThetaHBins, kThetaHCount)] += e * e;
    b.by_psi[BinOf(2 * hd.theta_d, kPsiBins, kPsiCount)] += e * e;
    b.fallback += fb ? e * e : 0;
    b.grazing += std::max(d.theta_i, d.theta_o) > 75 ? e * e : 0;
  }
  if (breakdown != nullptr && ref2 > 0) {
    for (double& x : b.by_theta_h) x /= ref2;
    for (double& x : b.by_psi) x /= ref2;
    b.fallback /= ref2;
    b.grazing /= ref2;
    *breakdown = b;
  }
  return ref2 > 0 ? std::sqrt(err2 / ref2) : 0;
}

Error Judge_(const std::vector<ReadingSoFar>& readings, const Truth& truth, const Judging& at) {
  const Judge judge(readings);
  Error e;
  int fallbacks = 0, ignored = 0;
  e.random = RelativeRms(judge, truth, at.random, &fallbacks, &e.breakdown);
  e.fallback = 100.0 * fallbacks / static_cast<double>(at.random.size());
  e.specular = RelativeRms(judge, truth, at.specular, &ignored);
  e.retro = RelativeRms(judge, truth, at.retro, &ignored);
  return e;
}

struct Stage {
  int readings = 0;
  double seconds = 0;
  int prompts = 0;
  double remaining = 0;  // the model's Remaining() for these readings
  Error error;
  Breakdown where;  // the readings' count by θh and ψ bins (--breakdown)
};

Breakdown WhereReadings(const std::vector<ReadingSoFar>& readings) {
  Breakdown b;
  for (const ReadingSoFar& r : readings) {
    const interp::HalfDiffAngles hd = interp::ToHalfDifference(ToIsotropic(r.directions));
    b.by_theta_h[BinOf(hd.theta_h, kThetaHBins, kThetaHCount)] += 1;
    b.by_psi[BinOf(2 * hd.theta_d + 0.01, kPsiBins, kPsiCount)] += 1;
  }
  return b;
}

void PrintStage(const char* label, const Stage& s, const Stage& grid, bool breakdown) {
  std::printf("  %-10s %6d %8.1f %5d %8.4f %8.4f %6.2f %8.4f %8.4f %6.1f %8.3f\n", label,
              s.readings, s.seconds / 60, s.prompts, s.error.random, s.error.specular,
              grid.error.random > 0 ? s.error.random / grid.error.random : 0, s.error.retro,
              s.remaining, s.error.fallback, s.seconds / std::max(grid.seconds, 1e-9));
  if (!breakdown) return;
  std::printf("  %-10s err² by θh", "");
  for (int i = 0; i < kThetaHCount; ++i) {
    std::printf(" [%g,%g) %.5f", kThetaHBins[i], std::floor(kThetaHBins[i + 1]),
                s.error.breakdown.by_theta_h[i]);
  }
  std::printf("\n  %-10s err² by ψ ", "");
  for (int i = 0; i < kPsiCount; ++i) {
    std::printf(" [%g,%g) %.5f", kPsiBins[i], std::floor(kPsiBins[i + 1]),
                s.error.breakdown.by_psi[i]);
  }
  std::printf("; unanswered %.5f; θ > 75° %.5f", s.error.breakdown.fallback,
              s.error.breakdown.grazing);
  std::printf("\n  %-10s reads by θh", "");
  for (double n : s.where.by_theta_h) std::printf(" %5.0f", n);
  std::printf("; by ψ");
  for (double n : s.where.by_psi) std::printf(" %5.0f", n);
  std::printf("\n");
}

struct Setup {
  v1::Plan adaptive_plan, grid_plan;
  plan::RigDescription rig;
  adaptive::AdaptiveSpec spec;
  double u = 0.015;
  bool verbose = false;
  bool breakdown = false;  // print where the error is (Breakdown)
  double candidate_step_deg = adaptive::kCandidateStepDeg;
  double candidate_theta_max = 0;  // the lattice's θ limit, if not the region's
  adaptive::RoundOptions round;    // its max_readings from the plan
  Judging judging;
  std::vector<double> stages = {10, 20, 30, 50};  // % of the grid's readings
};

Stage GridStage(const Setup& setup, const Truth& truth, std::mt19937_64& rng) {
  const Expanded grid = Expand(setup.grid_plan, setup.rig);
  std::vector<ReadingSoFar> readings;
  for (std::size_t i = 0; i < grid.poses.size(); ++i) {
    readings.push_back(Measure(truth, grid.poses[i], grid.directions[i], setup.u, rng));
  }
  const auto model = adaptive::MakeInterpolatedModel(setup.spec);
  return {static_cast<int>(readings.size()),
          grid.seconds,
          grid.prompts,
          model->Map(readings)->Remaining(),
          Judge_(readings, truth, setup.judging),
          WhereReadings(readings)};
}

// One round as chosen: its size, gain, cost and where its picks lie.
void PrintRound(const adaptive::Spend& spent, const adaptive::Round& round, double remaining) {
  std::printf(
      "    round at %d readings, %.0f s (U left %.4f): %zu picks, gain %.4f, %.0f s, %d prompts:",
      spent.readings, spent.seconds, remaining, round.poses.size(), round.predicted_gain,
      round.cost.seconds, round.cost.prompts);
  for (const adaptive::ChosenPose& p : round.poses) {
    const IsoDirection iso = ToIsotropic(PoseToDirections(p.pose));
    std::printf(" (%.0f %.0f %.0f|d%.0f %.4f)", iso.theta_i, iso.theta_o, iso.phi, p.pose.delta,
                p.predicted_gain);
  }
  std::printf("\n");
}

// The seed design of `setup.spec` (which may differ from the plan's: --seed-delta-every,
// --seed-per-delta) expanded as the plan expands its seed: a pose list with the plan's policies.
Expanded ExpandSeed(const Setup& setup) {
  v1::Plan seed = setup.adaptive_plan;
  seed.clear_method();
  v1::PoseList* list = seed.mutable_pose_list();
  for (const Pose& p : adaptive::SeedPoses(adaptive::MakeSeedDesign(setup.spec, setup.rig))) {
    v1::PoseEntry* e = list->add_poses();
    e->set_alpha(p.alpha);
    e->set_beta(p.beta);
    e->set_gamma(p.gamma);
    e->set_delta(p.delta);
  }
  return Expand(seed, setup.rig);
}

// The adaptive session: the seed, then rounds until each level of readings; one stage per level.
// Each round is chosen and expanded after the session's steps as the engine does it (NextRound:
// ChooseRound from the rig's state, then RoundSteps), and the spend is the steps' own.
std::vector<Stage> AdaptiveStages(const Setup& setup, const Truth& truth, std::mt19937_64& rng,
                                  const std::vector<int>& levels) {
  const Expanded seed = ExpandSeed(setup);
  std::vector<ReadingSoFar> readings;
  for (std::size_t i = 0; i < seed.poses.size(); ++i) {
    readings.push_back(Measure(truth, seed.poses[i], seed.directions[i], setup.u, rng));
  }
  const v1::Plan& plan = setup.adaptive_plan;
  std::vector<plan::Step> steps = seed.steps;
  adaptive::Spend spent = adaptive::SpendOfSteps(steps, plan, setup.rig);
  adaptive::AdaptiveSpec wide = setup.spec;  // --candidate-theta-max: the candidates' region
  if (setup.candidate_theta_max > 0) {
    wide.region.theta_i_max_deg = wide.region.theta_o_max_deg = setup.candidate_theta_max;
  }
  const std::vector<Pose> candidates =
      adaptive::CandidatePoses(wide, setup.rig, setup.candidate_step_deg);
  const adaptive::RoundCost cost(plan, setup.rig);
  const auto model = adaptive::MakeInterpolatedModel(setup.spec);
  std::vector<Stage> stages;
  for (int level : levels) {
    while (spent.readings < level) {
      const plan::ExpansionStart start = plan::StartAfter(steps, plan, setup.rig);
      const adaptive::Budget budget{level, 0, 0};
      adaptive::Round round = adaptive::ChooseRound(
          {readings, candidates, start.model, spent, budget}, *model, cost, setup.round);
      const std::vector<plan::Step> added =
          adaptive::RoundSteps(plan, setup.rig, steps, spent, start, budget, round);
      if (round.poses.empty()) break;
      if (setup.verbose) PrintRound(spent, round, model->Map(readings)->Remaining());
      for (const adaptive::ChosenPose& p : round.poses) {
        readings.push_back(Measure(truth, p.pose, PoseToDirections(p.pose), setup.u, rng));
      }
      steps.insert(steps.end(), added.begin(), added.end());
      spent = adaptive::SpendOfSteps(steps, plan, setup.rig);
    }
    stages.push_back({spent.readings, spent.seconds, spent.prompts,
                      model->Map(readings)->Remaining(), Judge_(readings, truth, setup.judging),
                      WhereReadings(readings)});
  }
  return stages;
}

void RunMaterial(const Setup& setup, const std::string& path, const std::vector<int>& seeds) {
  Result<material::Material> m = sim::LoadMaterialFile(path);
  if (!m.ok()) Fail(path + ": " + m.status().message());
  const Truth truth(std::move(*m));
  for (int seed : seeds) {
    std::printf("%s (%s), seed %d\n", truth.name().c_str(), path.c_str(), seed);
    std::printf("  %-10s %6s %8s %5s %8s %8s %6s %8s %8s %6s %8s\n", "", "reads", "rig min",
                "prmpt", "err", "spec", "÷grid", "retro", "U left", "fb %", "÷time");
    std::mt19937_64 grid_rng(static_cast<std::uint64_t>(seed) * 1000003 + 1);
    const Stage grid = GridStage(setup, truth, grid_rng);
    PrintStage("grid", grid, grid, setup.breakdown);
    std::vector<int> levels;
    for (double percent : setup.stages) {
      levels.push_back(static_cast<int>(std::lround(percent / 100 * grid.readings)));
    }
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed) * 1000003 + 2);
    const std::vector<Stage> stages = AdaptiveStages(setup, truth, rng, levels);
    for (std::size_t i = 0; i < stages.size(); ++i) {
      const std::string label = "adapt " + std::to_string(std::lround(setup.stages[i])) + "%";
      PrintStage(label.c_str(), stages[i], grid, setup.breakdown);
    }
    std::fflush(stdout);
  }
}

double Seconds(std::chrono::steady_clock::time_point from) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count();
}

// Map() on 2,000 of the paper grid's readings (spread over it) of the glossy sample, and one round
// of 24 picks over 5,000 of the candidates; medians of `repeat`.
void Timing(const Setup& setup, int repeat) {
  const Expanded grid = Expand(setup.grid_plan, setup.rig);
  Result<material::Material> m = sim::LoadMaterialFile("deploy/materials/glossy.toml");
  if (!m.ok()) Fail(m.status().message());
  const Truth glossy(std::move(*m));
  std::mt19937_64 rng(1);
  std::vector<ReadingSoFar> readings;
  for (std::size_t k = 0; k < 2000 && k < grid.poses.size(); ++k) {
    const std::size_t i = k * grid.poses.size() / 2000;  // spread over the whole grid
    readings.push_back(Measure(glossy, grid.poses[i], grid.directions[i], setup.u, rng));
  }
  // A 4° lattice: the plan's 5° one holds fewer than 5,000 candidates.
  std::vector<Pose> candidates = adaptive::CandidatePoses(setup.spec, setup.rig, 4);
  const std::size_t all = candidates.size();
  std::vector<Pose> some;
  for (std::size_t i = 0; i < all && some.size() < 5000;
       i += std::max<std::size_t>(1, all / 5000)) {
    some.push_back(candidates[i]);
  }
  const adaptive::RoundCost cost(setup.adaptive_plan, setup.rig);
  const auto model = adaptive::MakeInterpolatedModel(setup.spec);
  adaptive::RoundOptions round_options = setup.round;
  round_options.max_readings = 24;
  std::vector<double> map_s, round_s, map_cpu, round_cpu;
  for (int r = 0; r < repeat; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    std::clock_t c0 = std::clock();
    const auto map = model->Map(readings);
    map_s.push_back(Seconds(t0));
    map_cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    t0 = std::chrono::steady_clock::now();
    c0 = std::clock();
    const adaptive::Round round = adaptive::ChooseRound(
        {readings, some, readings.back().pose, {}, {100000, 0, 0}}, *model, cost, round_options);
    round_s.push_back(Seconds(t0));
    round_cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    if (round.poses.size() != 24) Fail("round of " + std::to_string(round.poses.size()));
  }
  for (auto* v : {&map_s, &round_s, &map_cpu, &round_cpu}) std::sort(v->begin(), v->end());
  const std::size_t mid = map_s.size() / 2;
  std::printf(
      "readings=%zu candidates=%zu (of %zu) map_s=%.3f round_s=%.3f (a Map and 24 picks) "
      "map_cpu_s=%.3f round_cpu_s=%.3f repeat=%d (medians)\n",
      readings.size(), some.size(), all, map_s[mid], round_s[mid], map_cpu[mid], round_cpu[mid],
      repeat);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The adaptive planner's loop against the paper grid, without a rig"};
  Setup setup;
  std::vector<std::string> materials;
  std::vector<int> seeds = {1};
  std::string adaptive_path = "examples/plans/adaptive.json";
  std::string grid_path = "examples/plans/paper-grid.json";
  int directions = 20000;
  double u = 0.015;
  bool timing = false;
  int repeat = 3;
  app.add_option("--material", materials, "material files (brdf-sim's format)");
  app.add_option("--seeds", seeds, "noise seeds, one session each");
  app.add_option("--plan", adaptive_path, "the adaptive plan (its region, δ, seed, rounds)");
  app.add_option("--grid", grid_path, "the fixed plan compared with");
  app.add_option("--directions", directions, "random direction pairs judged");
  double judge_theta_max = 80;  // the daemon benchmark's judging (daemon_bench_error.py)
  app.add_option("--judge-theta-max", judge_theta_max,
                 "judge at θi, θo up to this (default 80, as the daemon benchmark; 0: the plan's "
                 "region)");
  app.add_option("--u", u, "each reading's relative standard uncertainty");
  app.add_flag("--timing", timing, "time Map and a round instead");
  app.add_flag("--verbose", setup.verbose, "print every round's picks");
  app.add_flag("--breakdown", setup.breakdown,
               "print each stage's squared error by θh and by the lamp–detector angle ψ");
  app.add_option("--candidate-step", setup.candidate_step_deg,
                 "the candidates' lattice step, degrees (the planner's: 5)");
  app.add_option("--repeat", repeat, "timing repetitions");
  app.add_option("--candidate-theta-max", setup.candidate_theta_max,
                 "the 5° lattice's candidates up to this θi, θo (the model and the finer "
                 "candidates keep the plan's region)");
  app.add_option("--refine-levels", setup.round.refine.levels,
                 "levels of finer candidates a round adds (refine_candidates.h; 0: none)");
  int seed_every = 0, seed_per_delta = 0;
  app.add_option("--seed-delta-every", seed_every,
                 "the seed's space-filling set at every n-th δ only (default: the plan's)");
  app.add_option("--seed-per-delta", seed_per_delta,
                 "the seed's space-filling readings per δ (default: the plan's)");
  app.add_option("--refine-keep", setup.round.refine.keep, "finer candidates kept per level");
  app.add_option("--max-relocations", setup.round.max_relocations,
                 "relocations (a prompt each) a round may make; -1: any (round_chooser.h)");
  app.add_option("--stages", setup.stages, "% of the grid's readings at which to judge, rising")
      ->check(CLI::Range(0.0, 100.0));
  app.add_flag("--detector-arm", setup.rig.has_detector_arm,
               "a motorized detector arm (δ moves are no prompt), as brdf-sim's rig");

  CLI11_PARSE(app, argc, argv);
  std::sort(setup.stages.begin(), setup.stages.end());
  setup.adaptive_plan = LoadPlan(adaptive_path);
  setup.grid_plan = LoadPlan(grid_path);
  if (!setup.adaptive_plan.has_adaptive()) Fail(adaptive_path + " is not an adaptive plan");
  setup.spec = adaptive::ResolveAdaptive(setup.adaptive_plan.adaptive());
  setup.u = u;
  if (seed_every > 0) setup.spec.seed_delta_every = seed_every;
  if (seed_per_delta > 0) setup.spec.readings_per_delta = seed_per_delta;
  setup.round.max_readings = setup.spec.round_readings;
  setup.round.refine.step_deg = setup.candidate_step_deg;
  if (timing) {
    Timing(setup, repeat);
    return 0;
  }
  setup.judging = JudgingDirections(setup.spec.region, directions, judge_theta_max);
  const double judged_theta_max = judge_theta_max > 0 ? judge_theta_max
                                                      : std::min(setup.spec.region.theta_i_max_deg,
                                                                 setup.spec.region.theta_o_max_deg);
  std::printf(
      "readings' u %.3f; judged by the octant method (φ mirrored) at %d random pairs, "
      "θ ≤ %g°; rig time by the plan timing model (prompts %.0f s); candidates every "
      "%g° (refined %d levels, %d kept each); seed at every %d-th δ, %d readings each; "
      "detector %s; at most %d relocation(s) a round; plan %s\n",
      u, directions, judged_theta_max, setup.rig.operator_action_s, setup.candidate_step_deg,
      setup.round.refine.levels, setup.round.refine.keep, setup.spec.seed_delta_every,
      setup.spec.readings_per_delta, setup.rig.has_detector_arm ? "on a motorized arm" : "by hand",
      setup.round.max_relocations, adaptive_path.c_str());
  for (const std::string& path : materials) RunMaterial(setup, path, seeds);
  return 0;
}
