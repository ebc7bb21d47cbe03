#include "core/export/merl/writer.h"

#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/export/grid/npy_writer.h"
#include "core/geometry.h"

namespace brdf::exports {
namespace {

// Per-cell outcome, kept so that the counts are taken after the parallel run (deterministic).
// Low 6 bits: the source's InterpStatus; flags above.
constexpr std::uint8_t kBelowHorizon = 0x40;
constexpr std::uint8_t kClamped = 0x80;
constexpr std::uint8_t kStatusMask = 0x3f;
// Cells per chunk, whose cells above the horizon (about half) go as one SpectrumSource::Spectra
// batch: enough for the octant method to sort them by cell (core/interp/octant/octant.h: a quarter
// of a query per cell, about 12,500 for 50,000 readings with their reciprocity images, MERL's
// default), few enough for a progress report every 1/22 of the table and a prompt cancel.
constexpr std::size_t kBatchCells = 65536;

}  // namespace

std::size_t MerlReport::unfilled_total() const {
  std::size_t n = 0;
  for (const auto& [status, count] : unfilled) n += count;
  return n;
}

std::string MerlReport::Summary() const {
  std::string s = std::to_string(cells) + " cells: " + std::to_string(filled) + " filled, " +
                  std::to_string(below_horizon) + " below the horizon, " +
                  std::to_string(unfilled_total()) + " unfilled";
  std::string parts;
  for (const auto& [status, n] : unfilled) {
    if (!parts.empty()) parts += ", ";
    parts += std::to_string(n) + " " + interp::InterpStatusName(status);
  }
  if (!parts.empty()) s += " (" + parts + ")";
  s += ", " + std::to_string(clamped) + " clamped to the sRGB gamut; missing cells hold −1";
  return s;
}

Result<MerlExport> BuildMerlTable(const SpectrumSource& source, const WavelengthGrid& bands,
                                  const SpectralRgbWeights& rgb, const RunControl& control,
                                  const CallContext& ctx) {
  if (!bands.valid() || !(rgb.grid() == bands)) {
    return InvalidArgument(
        "MERL export: the RGB weights were made for another wavelength grid than the session's; "
        "make them with SpectralRgbWeights::Make on the session's grid");
  }
  MerlExport result;
  std::vector<double>& stored = result.table.stored;
  std::vector<std::uint8_t> outcome(kMerlCells, 0);
  const std::size_t nb = bands.count;
  const double inv_scale[3] = {1.0 / kMerlRedScale, 1.0 / kMerlGreenScale, 1.0 / kMerlBlueScale};

  ProgressReporter progress(control.progress, kMerlCells);
  BRDF_RETURN_IF_ERROR(ParallelForChunks(
      kMerlCells, kBatchCells, ResolveThreads(control.threads), ctx, &progress, 0, "MERL table",
      [&](std::size_t begin, std::size_t end) {
        // The chunk's cells above the horizon, answered as one batch (SpectrumSource::Spectra).
        std::vector<std::size_t> cells;
        std::vector<double> directions;
        cells.reserve(end - begin);
        directions.reserve(3 * (end - begin));
        for (std::size_t cell = begin; cell < end; ++cell) {
          const int k = static_cast<int>(cell % kMerlPhiDiffRes);
          const int j = static_cast<int>((cell / kMerlPhiDiffRes) % kMerlThetaDiffRes);
          const int i = static_cast<int>(cell / (std::size_t{kMerlPhiDiffRes} * kMerlThetaDiffRes));
          const MerlCellDirections at = CellDirections(i, j, k);
          if (!at.above) {
            outcome[cell] = kBelowHorizon;
            continue;
          }
          const IsoDirection iso = ToIsotropic(at.directions);
          cells.push_back(cell);
          directions.insert(directions.end(), {iso.theta_i, iso.theta_o, iso.phi});
        }
        std::vector<interp::InterpStatus> statuses(cells.size());
        std::vector<double> spectra(cells.size() * nb);
        source.Spectra(directions, statuses, spectra);
        for (std::size_t q = 0; q < cells.size(); ++q) {
          const std::size_t cell = cells[q];
          const interp::InterpStatus st = statuses[q];
          outcome[cell] = static_cast<std::uint8_t>(st);
          if (st != interp::InterpStatus::kOk) continue;
          const Rgb c = rgb.Apply(std::span<const double>(spectra).subspan(q * nb, nb));
          const double channel[3] = {c.r, c.g, c.b};
          for (int ch = 0; ch < 3; ++ch) {
            double v = channel[ch];
            if (!(v >= 0)) {  // negative (out of gamut, noise) or NaN
              v = 0;
              outcome[cell] |= kClamped;
            }
            stored[static_cast<std::size_t>(ch) * kMerlCells + cell] = v * inv_scale[ch];
          }
        }
      }));

  MerlReport& report = result.report;
  for (std::uint8_t o : outcome) {
    if (o & kBelowHorizon) {
      ++report.below_horizon;
      continue;
    }
    const auto st = static_cast<interp::InterpStatus>(o & kStatusMask);
    if (st != interp::InterpStatus::kOk) {
      ++report.unfilled[st];
      continue;
    }
    ++report.filled;
    if (o & kClamped) ++report.clamped;
  }
  progress.Finish();
  return result;
}

Status WriteMerl(const MerlTable& table, std::ostream& out) {
  if (table.stored.size() != 3 * kMerlCells) {
    return Internal("MERL table holds " + std::to_string(table.stored.size()) +
                    " values instead of 3 · 90 · 90 · 180");
  }
  std::string head;
  for (std::int32_t dim : {kMerlThetaHalfRes, kMerlThetaDiffRes, kMerlPhiDiffRes}) {
    const auto u = static_cast<std::uint32_t>(dim);
    for (int b = 0; b < 4; ++b) head += static_cast<char>((u >> (8 * b)) & 0xff);
  }
  out.write(head.data(), static_cast<std::streamsize>(head.size()));
  std::string buffer;
  constexpr std::size_t kBlock = 1 << 16;
  for (std::size_t at = 0; at < table.stored.size() && out; at += kBlock) {
    const std::size_t n = std::min(kBlock, table.stored.size() - at);
    buffer.clear();
    AppendLittleEndian(std::span<const double>(table.stored.data() + at, n), buffer);
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  }
  out.flush();
  if (!out) return IoError("writing the MERL .binary failed: is the disk full or read-only?");
  return Status::Ok();
}

}  // namespace brdf::exports
