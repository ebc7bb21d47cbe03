// The MERL BRDF database's ".binary" layout, as its reference reader (BRDFRead.cpp, MERL 2005)
// defines it. Everything here mirrors that reader, so that what we write is what it reads:
//
//   file    = int32 dims[3] = {90, 90, 180}, then 3 · 90 · 90 · 180 doubles (little-endian),
//             channel-major: all red values, then all green, then all blue;
//   index   = φd index + θd index · 180 + θh index · 180 · 90 (within a channel);
//   value   = stored · scale, with RED_SCALE 1/1500, GREEN_SCALE 1.15/1500, BLUE_SCALE 1.66/1500
//             (the reader multiplies, so a writer divides); negative = no data (MERL writes −1).
//
// Coordinates are Rusinkiewicz's half/difference angles: the half vector h = (ωi + ωo)/|ωi + ωo|
// at (θh, φh), and the difference vector d = Ry(−θh) · Rz(−φh) · ωi at (θd, φd). The indices:
//   θh: ⌊√(θh / 90° · 90) · √90⌋ = ⌊√(θh° · 90)⌋ (non-linear: finer near the specular peak),
//   θd: ⌊θd / 90° · 90⌋,
//   φd: ⌊φd / 180° · 180⌋ after φd += 180° when negative (reciprocity: φd and φd + π are the
//       same pair of directions with ωi and ωo swapped),
// each clamped to its range. φh is ignored (isotropic BRDFs). Radians, as in the reader.
#pragma once

#include <cstddef>
#include <vector>

#include "core/pose.h"

namespace brdf::exports {

inline constexpr int kMerlThetaHalfRes = 90;
inline constexpr int kMerlThetaDiffRes = 90;
inline constexpr int kMerlPhiDiffRes = 180;  // the reader's BRDF_SAMPLING_RES_PHI_D / 2
inline constexpr std::size_t kMerlCells =
    std::size_t{kMerlThetaHalfRes} * kMerlThetaDiffRes * kMerlPhiDiffRes;
inline constexpr std::size_t kMerlFileBytes = 3 * 4 + 3 * 8 * kMerlCells;
inline constexpr double kMerlRedScale = 1.0 / 1500.0;
inline constexpr double kMerlGreenScale = 1.15 / 1500.0;
inline constexpr double kMerlBlueScale = 1.66 / 1500.0;
// MERL's convention for a cell without data (stored as is, not scaled).
inline constexpr double kMerlMissing = -1.0;

// The three channels as stored in the file (value / scale; kMerlMissing where there is no data):
// stored[c · kMerlCells + MerlIndex(…)] for channel c = 0 (red), 1 (green), 2 (blue).
struct MerlTable {
  std::vector<double> stored = std::vector<double>(3 * kMerlCells, kMerlMissing);
};

struct HalfDiff {
  double theta_half = 0, phi_half = 0, theta_diff = 0, phi_diff = 0;  // radians
};

// The reader's std_coords_to_half_diff_coords (radians in, radians out).
HalfDiff StdToHalfDiff(double theta_in, double phi_in, double theta_out, double phi_out);

// The reader's index functions.
int MerlThetaHalfIndex(double theta_half);
int MerlThetaDiffIndex(double theta_diff);
int MerlPhiDiffIndex(double phi_diff);
// Position within one channel.
inline std::size_t MerlIndex(int theta_half_index, int theta_diff_index, int phi_diff_index) {
  return static_cast<std::size_t>(phi_diff_index) +
         static_cast<std::size_t>(theta_diff_index) * kMerlPhiDiffRes +
         static_cast<std::size_t>(theta_half_index) * kMerlPhiDiffRes * kMerlThetaDiffRes;
}

// The pair of directions a cell stands for: the centre of the cell in index space (θh =
// (i + ½)² / 90 degrees, θd = j + ½ degrees, φd = k + ½ degrees) with φh = 0, turned into
// (θi, φi, θo, φo) in degrees. Centres, not lower edges, so that the reader's truncation maps the
// directions back to the same cell (a lower edge may round into the cell below), and so that a
// lookup anywhere in the cell is at most half a cell away from where its value was taken.
// `above` is false when ωi or ωo is below the surface (θ > 90°): such a cell holds no BRDF.
struct MerlCellDirections {
  Directions directions;
  bool above = true;
};
MerlCellDirections CellDirections(int theta_half_index, int theta_diff_index, int phi_diff_index);

}  // namespace brdf::exports
