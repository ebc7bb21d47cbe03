#include "tools/brdf-interp/interp_command.h"

#include <chrono>

#include "core/interp/csv_table.h"
#include "tools/brdf-interp/batch.h"
#include "tools/brdf-interp/file_io.h"
#include "tools/brdf-interp/output_csv.h"
#include "tools/brdf-interp/tool_common.h"

namespace brdf::interp_tool {
namespace {

int Fail(std::ostream& err, const Status& status) {
  err << "brdf-interp: " << status.message() << "\n";
  return ExitCodeFor(status);
}

}  // namespace

int RunInterp(const InterpRequest& request, std::ostream& err) {
  const auto start = std::chrono::steady_clock::now();
  interp::Options options;
  options.mirror_phi = request.mirror_phi;
  options.reciprocity = request.reciprocity;
  Result<interp::Coordinates> coordinates = interp::ParseCoordinates(request.coordinates);
  if (!coordinates.ok()) return Fail(err, coordinates.status().WithContext("--coordinates"));
  options.coordinates = *coordinates;
  Result<interp::Trend> trend = interp::ParseTrend(request.trend);
  if (!trend.ok()) return Fail(err, trend.status().WithContext("--trend"));
  options.trend = *trend;
  if (!request.scale.empty()) {
    Result<std::vector<double>> scale = ParseNumberList(request.scale, "--scale");
    if (!scale.ok()) return Fail(err, scale.status());
    options.axis_scale = *scale;
  }

  Result<std::string> samples_text = ReadFile(request.samples_path);
  if (!samples_text.ok()) return Fail(err, samples_text.status());
  Result<interp::SampleTable> samples =
      interp::ParseSamplesCsv(*samples_text, request.samples_path);
  if (!samples.ok()) return Fail(err, samples.status());
  samples_text = std::string();  // free it

  Result<std::string> queries_text = ReadFile(request.queries_path);
  if (!queries_text.ok()) return Fail(err, queries_text.status());
  Result<interp::QueryTable> queries = interp::ParseQueriesCsv(*queries_text, request.queries_path);
  if (!queries.ok()) return Fail(err, queries.status());
  queries_text = std::string();

  if (queries->dims != samples->dims) {
    return Fail(
        err,
        InvalidArgument(request.queries_path + " has " + std::to_string(queries->dims) +
                        " coordinate columns but " + request.samples_path + " has " +
                        std::to_string(samples->dims) + "; queries need the samples' coordinates"));
  }

  Result<std::unique_ptr<interp::Interpolator>> interpolator =
      MakeNamedInterpolator(request.method, samples->samples, options);
  if (!interpolator.ok()) {
    return Fail(err, interpolator.status().WithContext("--method " + request.method + " on " +
                                                       request.samples_path));
  }

  OutputLayout layout;
  layout.dims = samples->dims;
  layout.wavelength_headers = samples->wavelength_headers;
  if (request.explain) {
    layout.explain_vertices = MaxVertices((*interpolator)->method(), samples->dims);
  }
  Result<OutputFile> out = OutputFile::Open(request.output_path);
  if (!out.ok()) return Fail(err, out.status());
  Status s = out->Write(FormatHeader(layout));
  BatchCounts counts;
  if (s.ok()) {
    s = RunBatch(
        **interpolator, *queries, layout, request.threads,
        [&](std::string_view rows) { return out->Write(rows); }, &counts);
  }
  if (s.ok()) s = out->Close();
  if (!s.ok()) return Fail(err, s);

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  err << "brdf-interp: " << counts.total() << " queries (" << request.method << ", "
      << samples->samples->size() << " samples, " << request.threads << " thread"
      << (request.threads == 1 ? "" : "s") << ", " << seconds << " s):";
  for (std::size_t k = 0; k < counts.by_status.size(); ++k) {
    if (counts.by_status[k] == 0) continue;
    err << " " << counts.by_status[k] << " "
        << interp::InterpStatusName(static_cast<interp::InterpStatus>(k));
  }
  err << " → " << out->name() << "\n";
  return kExitOk;
}

}  // namespace brdf::interp_tool
