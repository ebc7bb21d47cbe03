// brdf-export: a session's readings out to the tools a lab already uses (README.md).
//   brdf-export --db PATH --session N csv  [--quantity radiance|reflectance|brdf] -o OUT.csv
//   brdf-export --db PATH --session N grid [--steps 1,1,1] [--nodes] [--method M] -o OUT.npy
//   brdf-export --db PATH --session N rgl [--rgb] [--method M] -o OUT.bsdf
//   brdf-export --db PATH --session N merl [--method M] [--probe θi,φi,θo,φo]… -o OUT.binary
//   brdf-export --db PATH --session N fit  [--model lambert|cook-torrance|both] -o OUT.csv
//   brdf-export fit --readings READINGS.csv [--model …] -o OUT.csv
//   (--demo instead of --db/--session: a synthetic paint-like session on the paper's grid)
#include <CLI/CLI.hpp>
#include <iostream>

#include "tools/brdf-export/export_commands.h"

namespace {

using namespace brdf::export_tool;

constexpr const char* kFooter = R"(
Angles in degrees (geometry convention of docs/geometry.md); radiance in
W·m⁻²·sr⁻¹·nm⁻¹, BRDF in sr⁻¹; every text export documents its units in '#' header lines.
Files are written as OUT.partial and renamed when complete. Exit status: 0 done, 2 the request
cannot work as given (bad value, unknown or empty session), 1 other failures (I/O, database).)";

void AddInterpOptions(CLI::App& app, InterpChoice& c, bool reciprocity_by_default) {
  app.add_option("--method", c.method,
                 "interpolation method: octant (the paper's), delaunay, nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}))
      ->capture_default_str();
  app.add_option("--scale", c.scale, "per-axis multipliers a,b,c applied before distances");
  app.add_flag("--mirror-phi", c.mirror_phi,
               "add the mirrored copies (θi, θo, −φ) and (θi, θo, 360° − φ)");
  app.add_option("--coordinates", c.coordinates,
                 "interpolate in incidence (θi, θo, φ) or half-diff (Rusinkiewicz's "
                 "half/difference angles) coordinates")
      ->check(CLI::IsMember({"incidence", "half-diff"}))
      ->capture_default_str();
  app.add_option("--trend", c.trend,
                 "none, or bivariate: blend the readings' residuals from a fitted smooth "
                 "f(θh, θd) and add it back")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();
  app.add_option("--fill", c.fill,
                 "cells the method cannot fill: none (left NaN / −1) or chain (Delaunay, then the "
                 "fitted Cook-Torrance model)")
      ->check(CLI::IsMember({"none", "chain"}))
      ->capture_default_str();
  if (reciprocity_by_default) {
    // A MERL cell stands for a pair of directions and its swap alike (φd and φd + π share it):
    // the interpolator gets the swapped copies so that its answer is reciprocal too.
    c.reciprocity = true;
    app.add_flag("--reciprocity,!--no-reciprocity", c.reciprocity,
                 "add the swapped copies (θo, θi, φ) (default on: MERL tables are reciprocal)");
  } else {
    app.add_flag("--reciprocity", c.reciprocity, "add the swapped copies (θo, θi, φ)");
  }
}

// The fit subcommand and its options.
CLI::App* AddFitCommand(CLI::App& app, FitCommandOptions& fit) {
  CLI::App* fit_cmd =
      app.add_subcommand("fit", "fit Lambert and Cook-Torrance (GGX) per wavelength; CSV report");
  fit_cmd->add_option("--model", fit.model, "lambert, cook-torrance or both")
      ->check(CLI::IsMember({"lambert", "cook-torrance", "both"}))
      ->capture_default_str();
  fit_cmd->add_flag("--per-band", fit.per_band,
                    "fit the roughness α and F0 per band (default: shared by all bands)");
  fit_cmd->add_option("--readings", fit.readings_csv,
                      "fit a readings CSV of the BRDF (brdf-export csv, brdfctl export) instead "
                      "of --db/--session; its u_<λ> columns weight the fit");
  return fit_cmd;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "brdf-export: export a brdfd session (CSV, NumPy .npy grid, MERL .binary) and "
      "fit reflection models to it"};
  app.footer(kFooter);
  app.require_subcommand(1);
  CommonOptions common;
  app.add_option("--db", common.db_path, "the brdfd SQLite database");
  app.add_option("--session", common.session_id, "session id");
  app.add_flag("--demo", common.demo,
               "use a synthetic session (the analytic paint-like sample on the paper's grid)");
  app.add_option("-o,--output", common.output, "output file ('-': standard output, text only)")
      ->required();
  app.add_option("--threads", common.threads, "threads (0: one per hardware thread)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_flag("--quiet", common.quiet, "no progress line");
  app.add_flag("--exclude-flagged", common.exclude_flagged,
               "leave out readings the quality policy flagged");

  CsvOptions csv;
  CLI::App* csv_cmd = app.add_subcommand("csv", "one row per reading, spectrum columns by nm");
  csv_cmd->add_option("--quantity", csv.quantity, "radiance (all readings, raw), reflectance, brdf")
      ->capture_default_str();

  GridOptions grid;
  CLI::App* grid_cmd =
      app.add_subcommand("grid", "resample onto a regular (θi, θo, φ) grid: .npy or CSV");
  grid_cmd->add_option("--quantity", grid.quantity, "radiance, reflectance or brdf")
      ->capture_default_str();
  AddInterpOptions(*grid_cmd, grid.interp, false);
  grid_cmd->add_option("--steps", grid.steps, "dθi,dθo,dφ in degrees (or one value for all)")
      ->capture_default_str();
  grid_cmd->add_flag("--nodes", grid.nodes,
                     "sample the nodes 0, step, …, 90 (180) instead of the cell centres");
  grid_cmd->add_option("--format", grid.format, "npy or csv (default: from -o's extension)");
  grid_cmd->add_flag("--float32", grid.float32,
                     "npy: float32 instead of float64, half the bytes (the .json says dtype)");
  grid_cmd->add_flag("--uncertainty", grid.uncertainty,
                     "npy: also OUT.u.npy, OUT.u_measurement.npy and OUT.u_interpolation.npy "
                     "(standard uncertainties, k = 1; the .json's \"uncertainty\" says what)");

  MerlOptions merl;
  CLI::App* merl_cmd = app.add_subcommand(
      "merl", "MERL .binary (90 × 90 × 180 half-angle table, linear sRGB under D65)");
  AddInterpOptions(*merl_cmd, merl.interp, true);
  merl_cmd->add_option("--colord", merl.colord_dir, "where colord-data's CIE tables are")
      ->capture_default_str();
  merl_cmd->add_option("--probe", merl.probes,
                       "θi,φi,θo,φo: print the interpolated RGB and the file's RGB there");

  RglCommandOptions rgl;
  CLI::App* rgl_cmd = app.add_subcommand(
      "rgl", "RGL material .bsdf (Dupuy & Jakob 2018; Mitsuba 3, pbrt-v4), spectral or --rgb");
  AddInterpOptions(*rgl_cmd, rgl.interp, true);
  rgl_cmd->add_flag("--rgb", rgl.rgb, "linear sRGB under D65 (field rgb) instead of spectra");
  rgl_cmd->add_option("--colord", rgl.colord_dir, "where colord-data's CIE tables are (--rgb)")
      ->capture_default_str();
  rgl_cmd->add_option("--theta-i", rgl.theta_i_count, "θi slices")->capture_default_str();
  rgl_cmd->add_option("--resolution", rgl.sample_res, "nodes per side of the warped square")
      ->capture_default_str();

  FitCommandOptions fit;
  CLI::App* fit_cmd = AddFitCommand(app, fit);

  for (CLI::App* sub : {csv_cmd, grid_cmd, merl_cmd, rgl_cmd, fit_cmd}) sub->fallthrough();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitInvalid;
  }
  if (csv_cmd->parsed()) return RunCsv(common, csv, std::cerr);
  if (grid_cmd->parsed()) return RunGrid(common, grid, std::cerr);
  if (merl_cmd->parsed()) return RunMerl(common, merl, std::cout, std::cerr);
  if (rgl_cmd->parsed()) return RunRgl(common, rgl, std::cerr);
  return RunFit(common, fit, std::cerr);
}
