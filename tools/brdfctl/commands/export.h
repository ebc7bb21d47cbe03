// `brdfctl export <id> csv|grid|merl|rgl [-o FILE]`: a session exported by the daemon (Data.Export)
// and written to a local file, so that it works from any machine that reaches brdfd:
//   csv   the readings, one row each (pose, directions, quality, spectrum; units in the header)
//   grid  the session's interpolator on a regular (θi, θo, φ) grid, as .npy (with FILE.json
//         describing axes, wavelengths and unit) or CSV; NaN where the method cannot fill a cell
//   merl  a MERL .binary (90 × 90 × 180, linear sRGB under D65)
//   rgl   an RGL material .bsdf (Mitsuba 3, pbrt-v4; docs/rgl-format.md), spectral or --rgb
// Grid, merl and rgl fill the cells the method cannot with --fill chain (the default: Delaunay,
// then the fitted Cook-Torrance model) or leave them (--fill none); the report counts each.
// The formats are core/export's, the same as brdf-export's (tools/brdf-export/README.md).
// While the daemon works, a progress line shows the stage, the fraction done and the bytes
// received (redrawn on a terminal, one line per 10 % otherwise). The file is written as
// FILE.partial and renamed when the daemon's report arrives and the byte count matches, so a
// failed or interrupted export never leaves a truncated FILE. Without -o, FILE is the name the
// daemon suggests (session-<id>-grid-brdf.npy, …) in the current directory; "-o -" writes to
// standard output. The report (counts, NaN cells, readings left out) goes to standard error, or
// to standard output as one JSON line with --json.
#pragma once

#include <string>
#include <vector>

#include "tools/brdfctl/command.h"
#include "tools/brdfctl/command_context.h"

namespace brdf::ctl {

struct ExportOptions {
  std::string session_id;
  std::string what;               // csv, grid, merl, rgl
  std::string output;             // empty: the daemon's file name; "-": standard output
  std::string quantity = "brdf";  // radiance, reflectance, brdf (csv, grid)
  std::string format;             // grid: npy or csv; empty: from the output's extension
  std::vector<double> steps;      // grid: dθi,dθo,dφ in degrees, or one for all; empty: 1°
  bool nodes = false;             // grid: nodes 0…90 (180) instead of cell centres
  std::string method = "octant";  // grid, merl, rgl: octant, delaunay, nearest
  std::vector<double> axis_scale;
  bool mirror_phi = false;
  std::string coordinates = "incidence";  // grid, merl, rgl: incidence or half-diff
  std::string trend = "none";             // grid, merl, rgl: none or bivariate
  bool reciprocity = false;               // grid: also the θi↔θo swapped readings
  bool no_reciprocity = false;  // merl, rgl: reciprocity is on by default; this turns it off
  std::string fill = "chain";   // grid, merl, rgl: chain or none
  bool rgb = false;             // rgl: linear sRGB under D65 instead of spectra
  bool float32 = false;         // grid .npy: float32 instead of float64
  bool uncertainty = false;     // grid .npy, merl, rgl: the cells' u beside the file
  unsigned theta_i_count = 0;   // rgl: θi slices; 0: the daemon's default (24)
  unsigned resolution = 0;      // rgl: nodes per side of the warped square; 0: 48
  bool exclude_flagged = false;
  bool progress = true;       // draw the progress line on standard error
  bool progress_tty = false;  // redraw it in place (standard error is a terminal)
};

int RunExport(CommandContext& ctx, const ExportOptions& options);

// `export`, with its flags (command.h); the progress line is redrawn when standard error is a
// terminal.
void RegisterExportCommand(CommandRegistry& registry);

}  // namespace brdf::ctl
