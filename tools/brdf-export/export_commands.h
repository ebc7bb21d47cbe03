// The four exports of brdf-export, each a function of parsed options so that main.cc only parses
// the command line. Every one reads the session (or the synthetic demo session), computes, and
// writes its output atomically (output_file.h); long ones draw a progress line on stderr.
//
// Exit status: 0 done; 2 the request cannot work as given (a bad flag or value, bad grid steps,
// an unknown or empty session, no usable reading); 1 anything else (I/O, the database).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace brdf::export_tool {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitInvalid = 2;

struct CommonOptions {
  std::string db_path;  // the brdfd SQLite database (opened read-only in use)
  std::int64_t session_id = -1;
  bool demo = false;     // instead: the synthetic paint-like session on the paper's grid
  std::string output;    // file, or "-" for standard output (csv, fit)
  unsigned threads = 0;  // 0: one per hardware thread
  bool quiet = false;    // no progress line
  bool exclude_flagged = false;
};

struct InterpChoice {
  std::string method = "octant";  // octant, delaunay, nearest
  std::string scale;              // "a,b,c" or empty
  bool mirror_phi = false;
  bool reciprocity = false;
  // incidence or half-diff (interp::ParseCoordinates): where the method measures and blends.
  std::string coordinates = "incidence";
  std::string trend = "none";  // none or bivariate (core/interp/trend.h)
  // none: the method alone (holes stay NaN / −1); chain: then Delaunay, then the fitted
  // Cook-Torrance model (core/export/fill/chain.h).
  std::string fill = "chain";
};

struct CsvOptions {
  std::string quantity = "brdf";
};

struct GridOptions {
  std::string quantity = "brdf";
  InterpChoice interp;
  std::string steps = "1,1,1";  // dθi,dθo,dφ in degrees, or one value for all three
  bool nodes = false;           // grid nodes 0…90 (both ends) instead of cell centres
  std::string format;           // npy or csv; empty: from the output's extension (.csv → csv)
  bool float32 = false;         // npy: float32 instead of float64
  // npy: the uncertainty arrays OUT.u.npy, OUT.u_measurement.npy, OUT.u_interpolation.npy beside
  // OUT.npy, named in the .json's "uncertainty" (core/export/fill/uncertain_grid.h: the same
  // arrays as the daemon's export with include_uncertainty)
  bool uncertainty = false;
};

struct MerlOptions {
  InterpChoice interp;
  std::string colord_dir = "/usr/share/colord";
  std::vector<std::string> probes;  // "θi,φi,θo,φo": print interpolated and file RGB there
};

struct RglCommandOptions {
  InterpChoice interp;
  std::string colord_dir = "/usr/share/colord";
  bool rgb = false;  // an RGB file (linear sRGB under D65) instead of the spectral one
  std::size_t theta_i_count = 24;
  std::size_t sample_res = 48;
};

struct FitCommandOptions {
  std::string model = "both";  // lambert, cook-torrance, both
  bool per_band = false;       // α and F0 per band instead of shared
  // Instead of --db/--session: a readings CSV of the BRDF (brdf-export csv, brdfd's Data.Export
  // READINGS_CSV); its u_<λ> columns, when every row has them, weight the fit.
  std::string readings_csv;
};

// `out` receives what a command prints besides its file (probe rows); `err` messages/progress.
int RunCsv(const CommonOptions& common, const CsvOptions& options, std::ostream& err);
int RunGrid(const CommonOptions& common, const GridOptions& options, std::ostream& err);
int RunMerl(const CommonOptions& common, const MerlOptions& options, std::ostream& out,
            std::ostream& err);
// The RGL material (.bsdf, core/export/rgl/writer.h): the microfacet distribution from the
// session's retro-reflection readings, else from a fitted Cook-Torrance (GGX) model.
int RunRgl(const CommonOptions& common, const RglCommandOptions& options, std::ostream& err);
// Weighted by the readings' uncertainties (their budgets, or a CSV's u_<λ> columns) when every
// reading has one, else unweighted; the report says which, with χ²/dof when weighted.
int RunFit(const CommonOptions& common, const FitCommandOptions& options, std::ostream& err);

}  // namespace brdf::export_tool
