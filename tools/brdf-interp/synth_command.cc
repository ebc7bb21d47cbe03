#include "tools/brdf-interp/synth_command.h"

#include "core/interp/csv_table.h"
#include "tools/brdf-interp/file_io.h"
#include "tools/brdf-interp/output_csv.h"
#include "tools/brdf-interp/synthetic_samples.h"
#include "tools/brdf-interp/tool_common.h"

namespace brdf::interp_tool {

int RunSynth(const SynthRequest& request, std::ostream& err) {
  auto fail = [&err](const Status& s) {
    err << "brdf-interp synth: " << s.message() << "\n";
    return ExitCodeFor(s);
  };
  SyntheticPoints points;
  if (request.grid == "paper") {
    if (request.dims != 3) {
      return fail(InvalidArgument("--grid paper is the isotropic (3D) rig grid; drop --dims 4"));
    }
    Result<SyntheticPoints> grid = PaperGridPoints();
    if (!grid.ok()) return fail(grid.status());
    points = std::move(grid).value();
  } else if (request.grid == "random") {
    if (request.count == 0) {
      return fail(InvalidArgument("--grid random needs a point count, e.g. --grid random 50000"));
    }
    if (request.dims != 3 && request.dims != 4) {
      return fail(InvalidArgument("--dims must be 3 or 4"));
    }
    points = RandomPoints(request.count, request.seed, request.dims);
  } else {
    return fail(InvalidArgument("--grid '" + request.grid + "': use paper or random N"));
  }

  if (request.bands != 101 && request.bands != 201 && request.bands != 401) {
    return fail(InvalidArgument("--bands " + std::to_string(request.bands) +
                                ": use 101, 201 or 401 (380–780 nm every 4, 2 or 1 nm)"));
  }
  const WavelengthGrid wavelengths{380, 400.0 / static_cast<double>(request.bands - 1),
                                   request.bands};
  const auto d = static_cast<std::size_t>(points.dims);
  std::string text;
  for (const char* name : interp::CoordinateColumns(points.dims)) {
    if (!text.empty()) text += ',';
    text += name;
  }
  if (!request.coordinates_only) {
    for (std::size_t b = 0; b < wavelengths.count; ++b) {
      text += ',';
      AppendNumber(wavelengths.at(b), text);
    }
  }
  text += '\n';

  Result<OutputFile> out = OutputFile::Open(request.output_path);
  if (!out.ok()) return fail(out.status());
  const AnalyticBrdf brdf = SyntheticBrdf(points.dims);
  std::vector<double> spectrum(wavelengths.count);
  Status s;
  for (std::size_t i = 0; i < points.size() && s.ok(); ++i) {
    const std::span<const double> p(points.coords.data() + i * d, d);
    for (std::size_t j = 0; j < d; ++j) {
      if (j > 0) text += ',';
      AppendNumber(p[j], text);
    }
    if (!request.coordinates_only) {
      brdf.EvaluateSpectrum(PointDirections(p), wavelengths, spectrum);
      for (double v : spectrum) {
        text += ',';
        AppendNumber(v, text);
      }
    }
    text += '\n';
    if (text.size() > (1 << 20)) {
      s = out->Write(text);
      text.clear();
    }
  }
  if (s.ok()) s = out->Write(text);
  if (s.ok()) s = out->Close();
  if (!s.ok()) return fail(s);
  err << "brdf-interp synth: " << points.size() << " " << request.grid << " points"
      << (request.grid == "paper" ? " (" + std::to_string(points.poses) + " poses)" : "")
      << (request.coordinates_only
              ? std::string(", coordinates only")
              : ", " + std::to_string(wavelengths.count) + "-band analytic spectra")
      << " → " << out->name() << "\n";
  return kExitOk;
}

}  // namespace brdf::interp_tool
