// brdf-interp: interpolate scattered spectral BRDF samples at query points (README.md).
//   brdf-interp SAMPLES.csv QUERIES.csv [--method M] [--threads N] [--scale a,b,c[,d]]
//               [--mirror-phi] [--reciprocity] [--explain] [-o OUT.csv]
//   brdf-interp demo  [--method M] [--query θi,θo,φ] [...]    (also: brdf-interp --demo)
//   brdf-interp synth --grid paper|random N [--seed S] [--dims 3|4] [--bands 101|201|401]
//                     [--coordinates-only] -o F
#include <CLI/CLI.hpp>
#include <iostream>

#include "tools/brdf-interp/accuracy_command.h"
#include "tools/brdf-interp/demo_command.h"
#include "tools/brdf-interp/interp_command.h"
#include "tools/brdf-interp/synth_command.h"
#include "tools/brdf-interp/tool_common.h"

namespace {

using namespace brdf::interp_tool;

constexpr const char* kFooter = R"(
Samples CSV: theta_i,theta_o,phi (or theta_i,phi_i,theta_o,phi_o), then one column per
wavelength named by its value in nm; angles in degrees. Queries CSV: the coordinate columns only.
Output CSV: the query's coordinates, status (ok, empty_octant, no_enclosing_simplex,
outside_hull), one column per wavelength (empty unless ok); with --explain also v0..vK-1 (0-based
data rows of the blended samples), w0..wK-1 (their weights) and detail, where K = dims+1
(octant, delaunay) or 1 (nearest).
Exit status: 0 done (per-query failures are in the status column), 2 bad arguments or input
(the message names file, line and column), 1 system failure.)";

void AddMethodOptions(CLI::App& app, std::string& method, std::string& scale, bool& mirror,
                      bool& reciprocity, std::string& coordinates, std::string& trend) {
  app.add_option("--method", method,
                 "octant (the paper's), octant-reference (its O(N) scan), "
                 "delaunay, nearest")
      ->check(CLI::IsMember(MethodChoices()))
      ->capture_default_str();
  app.add_option("--scale", scale,
                 "per-axis multipliers a,b,c[,d] applied before distances are measured");
  app.add_flag("--mirror-phi", mirror, "add mirrored copies (θi, θo, −φ) (3D data only)");
  app.add_flag("--reciprocity", reciprocity, "add swapped copies (θo, θi, φ) (3D data only)");
  app.add_option("--coordinates", coordinates,
                 "incidence: interpolate in (θi, θo, φ); half-diff: in Rusinkiewicz's (θh, θd, "
                 "φd) (3D data only; --scale then scales (θh·cos φd, θh·sin φd, θd))")
      ->check(CLI::IsMember({"incidence", "half-diff"}))
      ->capture_default_str();
  app.add_option("--trend", trend,
                 "none, or bivariate: blend the samples' residuals from a fitted smooth "
                 "f(θh, θd) and add it back (3D data only)")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();
}

// The top level: SAMPLES.csv QUERIES.csv and their options (and --demo).
void AddInterpOptions(CLI::App& app, InterpRequest& interp, bool& demo_flag) {
  app.add_option("samples", interp.samples_path, "samples CSV");
  app.add_option("queries", interp.queries_path, "queries CSV");
  AddMethodOptions(app, interp.method, interp.scale, interp.mirror_phi, interp.reciprocity,
                   interp.coordinates, interp.trend);
  app.add_option("--threads", interp.threads, "threads evaluating queries (output order is fixed)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  app.add_flag("--explain", interp.explain, "add vertex rows, weights and detail columns");
  app.add_option("-o,--output", interp.output_path, "output CSV (default: standard output)");
  app.add_flag("--demo", demo_flag, "same as the demo subcommand");
}

CLI::App* AddDemoCommand(CLI::App& app, DemoRequest& demo) {
  CLI::App* demo_cmd = app.add_subcommand(
      "demo",
      "interpolate the analytic paint sample on the paper's rig grid and explain one answer");
  AddMethodOptions(*demo_cmd, demo.method, demo.scale, demo.mirror_phi, demo.reciprocity,
                   demo.coordinates, demo.trend);
  demo_cmd->add_option("--query", demo.query, "θi,θo,φ in degrees (default 37,52,128)");
  return demo_cmd;
}

CLI::App* AddAccuracyCommand(CLI::App& app, AccuracyRequest& accuracy) {
  CLI::App* accuracy_cmd = app.add_subcommand(
      "accuracy",
      "RMS and specular-peak error of every method, in (θi, θo, φ) and in (θh, θd, φd), against "
      "the analytic samples on the paper's rig grid");
  accuracy_cmd
      ->add_option("--sample", accuracy.sample,
                   "paint, glossy, glossy-ct, both (paint and glossy) or all")
      ->check(CLI::IsMember({"paint", "glossy", "glossy-ct", "both", "all"}))
      ->capture_default_str();
  accuracy_cmd->add_option("--queries", accuracy.queries, "random rig poses")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  accuracy_cmd->add_option("--seed", accuracy.seed, "random seed")->capture_default_str();
  accuracy_cmd->add_option("--scale", accuracy.scale, "axis scales for (θi, θo, φ)");
  accuracy_cmd->add_option("--half-scale", accuracy.half_scale,
                           "axis scales for (θh·cos φd, θh·sin φd, θd) (default 1,1,1)");
  accuracy_cmd
      ->add_option("--trend", accuracy.trend,
                   "none, or bivariate: every method blends the residuals from a fitted "
                   "T(θh, θd) and adds T back")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();
  accuracy_cmd
      ->add_option("--noise", accuracy.noise,
                   "scale each reading by (1 + NOISE · N(0, 1)), one draw per reading (a "
                   "meter's gain noise); the truth stays noiseless")
      ->capture_default_str();
  accuracy_cmd->add_flag("--mirror-phi", accuracy.mirror_phi, "add the mirrored copies");
  accuracy_cmd->add_flag("--reciprocity", accuracy.reciprocity, "add the swapped copies");
  accuracy_cmd
      ->add_option("--blend", accuracy.blend,
                   "linear (Σ w·f) or log (exp Σ w·log f, floored at 1e-6 of each band's "
                   "largest value) blend of the vertices' spectra; nearest is unaffected")
      ->check(CLI::IsMember({"linear", "log"}))
      ->capture_default_str();
  return accuracy_cmd;
}

CLI::App* AddSynthCommand(CLI::App& app, SynthRequest& synth, std::vector<std::string>& grid_args) {
  CLI::App* synth_cmd = app.add_subcommand("synth", "write a synthetic samples (or queries) CSV");
  synth_cmd->add_option("--grid", grid_args, "paper | random N")->required()->expected(1, 2);
  synth_cmd->add_option("--seed", synth.seed, "random seed")->capture_default_str();
  synth_cmd->add_option("--dims", synth.dims, "3 (θi,θo,φ) or 4 (θi,φi,θo,φo), random only")
      ->check(CLI::IsMember({3, 4}))
      ->capture_default_str();
  synth_cmd->add_flag("--coordinates-only", synth.coordinates_only,
                      "write the coordinate columns only (a queries file)");
  synth_cmd
      ->add_option("--bands", synth.bands,
                   "spectra on 380–780 nm: 101 (4 nm), 201 (2 nm) or 401 (1 nm) bands")
      ->capture_default_str();
  synth_cmd->add_option("-o,--output", synth.output_path, "output CSV (default: standard output)");
  return synth_cmd;
}

// synth with --grid's words: paper, or random and a count.
int RunSynthCommand(SynthRequest& synth, const std::vector<std::string>& grid_args) {
  synth.grid = grid_args.at(0);
  if (grid_args.size() == 2) {
    try {
      synth.count = static_cast<std::size_t>(std::stoull(grid_args[1]));
    } catch (const std::exception&) {
      std::cerr << "brdf-interp synth: --grid random N: '" << grid_args[1] << "' is not a count\n";
      return kExitUsage;
    }
  }
  return RunSynth(synth, std::cerr);
}

// --demo: the demo with the top level's method options.
int RunDemoFlag(const InterpRequest& interp, DemoRequest& demo) {
  demo.method = interp.method;
  demo.scale = interp.scale;
  demo.mirror_phi = interp.mirror_phi;
  demo.reciprocity = interp.reciprocity;
  demo.coordinates = interp.coordinates;
  demo.trend = interp.trend;
  return RunDemo(demo, std::cout, std::cerr);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "brdf-interp: interpolate scattered spectral BRDF samples (Sun & Wang's octant "
      "method, Delaunay, nearest neighbour)"};
  app.footer(kFooter);
  InterpRequest interp;
  bool demo_flag = false;
  AddInterpOptions(app, interp, demo_flag);
  DemoRequest demo;
  CLI::App* demo_cmd = AddDemoCommand(app, demo);
  AccuracyRequest accuracy;
  CLI::App* accuracy_cmd = AddAccuracyCommand(app, accuracy);
  SynthRequest synth;
  std::vector<std::string> grid_args;
  CLI::App* synth_cmd = AddSynthCommand(app, synth, grid_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  if (synth_cmd->parsed()) return RunSynthCommand(synth, grid_args);
  if (demo_cmd->parsed()) return RunDemo(demo, std::cout, std::cerr);
  if (accuracy_cmd->parsed()) return RunAccuracy(accuracy, std::cout, std::cerr);
  if (demo_flag) return RunDemoFlag(interp, demo);
  if (interp.samples_path.empty() || interp.queries_path.empty()) {
    std::cerr << "brdf-interp: give SAMPLES.csv and QUERIES.csv, or use `brdf-interp demo` or "
                 "`brdf-interp synth`; see --help\n";
    return kExitUsage;
  }
  return RunInterp(interp, std::cerr);
}
