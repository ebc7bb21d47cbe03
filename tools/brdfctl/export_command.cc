#include "tools/brdfctl/export_command.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/json_output.h"
#include "tools/brdfctl/rpc_error.h"
#include "tools/brdfctl/text_format.h"

namespace brdf::ctl {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int Invalid(std::ostream& err, const std::string& message) {
  err << "brdfctl export: " << message << "\n";
  return kExitInvalid;
}

std::string Megabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

// The request for the options, or an exit status and message for a bad option.
int BuildRequest(const ExportOptions& o, std::ostream& err, v1::ExportRequest* request) {
  request->set_session_id(o.session_id);
  const bool grid = o.what == "grid";
  if (o.what == "csv") {
    request->set_format(v1::EXPORT_FORMAT_READINGS_CSV);
  } else if (grid) {
    std::string format = o.format;
    if (format.empty()) format = EndsWith(o.output, ".csv") ? "csv" : "npy";
    if (format == "npy") {
      request->set_format(v1::EXPORT_FORMAT_GRID_NPY);
    } else if (format == "csv") {
      request->set_format(v1::EXPORT_FORMAT_GRID_CSV);
    } else {
      return Invalid(err, "--format '" + format + "': use npy or csv");
    }
  } else if (o.what == "merl") {
    request->set_format(v1::EXPORT_FORMAT_MERL_BINARY);
  } else if (o.what == "rgl") {
    request->set_format(v1::EXPORT_FORMAT_RGL_BSDF);
  } else {
    return Invalid(err, "'" + o.what + "': export csv, grid, merl or rgl");
  }

  if (o.quantity == "brdf") {
    request->set_quantity(v1::QUANTITY_BRDF);
  } else if (o.quantity == "reflectance") {
    request->set_quantity(v1::QUANTITY_REFLECTANCE);
  } else if (o.quantity == "radiance") {
    request->set_quantity(v1::QUANTITY_RADIANCE);
  } else {
    return Invalid(err, "--quantity '" + o.quantity + "': use radiance, reflectance or brdf");
  }
  const bool rgl = o.what == "rgl";
  if ((o.what == "merl" || rgl) && o.quantity != "brdf") {
    return Invalid(
        err, std::string(rgl ? "an RGL" : "a MERL") + " file holds the BRDF: leave out --quantity");
  }
  if (!rgl && (o.rgb || o.theta_i_count != 0 || o.resolution != 0)) {
    return Invalid(err, "--rgb, --theta-i and --resolution are for rgl exports");
  }
  request->set_rgb(o.rgb);
  request->set_rgl_theta_i_count(o.theta_i_count);
  request->set_rgl_resolution(o.resolution);
  if (o.fill == "chain") {
    request->set_fill(v1::EXPORT_FILL_CHAIN);
  } else if (o.fill == "none") {
    request->set_fill(v1::EXPORT_FILL_NONE);
  } else {
    return Invalid(err, "--fill '" + o.fill + "': use chain or none");
  }
  if (o.what == "csv" && o.fill != "chain") {
    return Invalid(err, "--fill is for grid, merl and rgl exports");
  }

  if (o.method == "octant") {
    request->set_method(v1::INTERPOLATION_METHOD_OCTANT);
  } else if (o.method == "delaunay") {
    request->set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  } else if (o.method == "nearest") {
    request->set_method(v1::INTERPOLATION_METHOD_NEAREST);
  } else {
    return Invalid(err, "--method '" + o.method + "': use octant, delaunay or nearest");
  }
  v1::InterpolationOptions* options = request->mutable_options();
  v1::InterpolationCoordinates coordinates{};
  if (!ParseCoordinatesName(o.coordinates, &coordinates)) {
    return Invalid(err, "--coordinates '" + o.coordinates + "': use incidence or half-diff");
  }
  if (o.what == "csv" && coordinates != v1::INTERPOLATION_COORDINATES_INCIDENCE) {
    return Invalid(err, "--coordinates is for grid, merl and rgl exports");
  }
  options->set_coordinates(coordinates);
  v1::InterpolationTrend trend{};
  if (!ParseTrendName(o.trend, &trend)) {
    return Invalid(err, "--trend '" + o.trend + "': use none or bivariate");
  }
  if (o.what == "csv" && trend != v1::INTERPOLATION_TREND_NONE) {
    return Invalid(err, "--trend is for grid, merl and rgl exports");
  }
  options->set_trend(trend);
  for (double s : o.axis_scale) options->add_axis_scale(s);
  options->set_mirror_phi(o.mirror_phi);
  // A MERL or RGL cell stands for a pair of directions and its swap alike (as brdf-export).
  options->set_reciprocity(o.what == "merl" || rgl ? !o.no_reciprocity : o.reciprocity);

  if (!o.steps.empty()) {
    if (!grid) return Invalid(err, "--steps is for grid exports");
    if (o.steps.size() != 1 && o.steps.size() != 3) {
      return Invalid(err, "--steps: give dθi,dθo,dφ in degrees (three values) or one for all");
    }
    const bool one = o.steps.size() == 1;
    request->set_step_theta_i(o.steps[0]);
    request->set_step_theta_o(one ? o.steps[0] : o.steps[1]);
    request->set_step_phi(one ? o.steps[0] : o.steps[2]);
  }
  request->set_grid_nodes(o.nodes);
  request->set_exclude_flagged(o.exclude_flagged);
  return kExitOk;
}

// The progress display: "export grid: resampling 45% [#########···········] 3.2 MB".
class ExportProgressLine {
 public:
  ExportProgressLine(std::ostream& err, std::string what, bool enabled, bool tty)
      : err_(err), what_(std::move(what)), enabled_(enabled), tty_(tty) {}

  void Update(const std::string& stage, double fraction, std::uint64_t bytes) {
    if (!enabled_) return;
    const int percent = static_cast<int>(std::floor(fraction * 100 + 1e-9));
    if (tty_) {
      constexpr int kWidth = 24;
      const int filled = std::min(kWidth, static_cast<int>(fraction * kWidth));
      err_ << "\r\033[Kexport " << what_ << ": " << stage << ' ' << percent << "% ["
           << std::string(static_cast<std::size_t>(filled), '#')
           << std::string(static_cast<std::size_t>(kWidth - filled), '-') << "] "
           << Megabytes(bytes) << std::flush;
      drawn_ = true;
    } else if (percent / 10 != last_decile_ || stage != last_stage_) {
      last_decile_ = percent / 10;
      last_stage_ = stage;
      err_ << "export " << what_ << ": " << stage << ' ' << percent << "%, " << Megabytes(bytes)
           << " received\n";
    }
  }

  // Ends the redrawn line so that what follows starts on a line of its own.
  void Finish() {
    if (drawn_) err_ << "\n";
    drawn_ = false;
  }

 private:
  std::ostream& err_;
  std::string what_;
  bool enabled_;
  bool tty_;
  bool drawn_ = false;
  int last_decile_ = -1;
  std::string last_stage_;
};

void PrintReport(std::ostream& err, const v1::ExportReport& r, const std::string& path) {
  err << "brdfctl export: " << r.summary() << " → " << path << " (" << r.bytes() << " bytes)\n";
  if (r.skipped_readings() > 0) {
    err << "brdfctl export: " << r.skipped_readings()
        << " sample readings left out; the first: " << r.first_skip_reason() << "\n";
  }
  if (r.shape_size() > 0) {
    err << "brdfctl export: shape (";
    for (int i = 0; i < r.shape_size(); ++i) err << (i > 0 ? ", " : "") << r.shape(i);
    err << ") float64, NaN cells: " << r.unfilled_cells() << "; axes, wavelengths, unit: " << path
        << ".json\n";
  }
  if (r.has_fill()) {
    const v1::ExportFillCounts& f = r.fill();
    char fraction[32];
    std::snprintf(fraction, sizeof fraction, "%.2f %%", 100 * f.model_fraction());
    err << "brdfctl export: fill " << f.policy() << ": " << f.interpolated() << " interpolated, "
        << f.fallback() << " fallback, " << f.model() << " model (" << fraction << "), "
        << f.empty() << " empty\n";
  }
}

}  // namespace

int RunExport(CommandContext& ctx, const ExportOptions& o) {
  v1::ExportRequest request;
  if (int rc = BuildRequest(o, ctx.err, &request); rc != kExitOk) return rc;
  const bool to_stdout = o.output == "-";
  if (to_stdout && (request.format() == v1::EXPORT_FORMAT_GRID_NPY ||
                    request.format() == v1::EXPORT_FORMAT_MERL_BINARY ||
                    request.format() == v1::EXPORT_FORMAT_RGL_BSDF)) {
    return Invalid(ctx.err, "a binary export needs a file: give -o FILE");
  }

  // Until the report names the file, bytes go to a .partial file (or standard output).
  const std::string partial =
      (o.output.empty() ? "brdfctl-export-" + o.session_id : o.output) + ".partial";
  std::ofstream file;
  if (!to_stdout) {
    file.open(partial, std::ios::binary | std::ios::trunc);
    if (!file) return Invalid(ctx.err, "cannot create " + partial + ": check the directory");
  }
  std::ostream& out = to_stdout ? ctx.out : file;
  auto fail = [&](int rc) {
    if (!to_stdout) {
      file.close();
      std::remove(partial.c_str());
    }
    return rc;
  };

  ExportProgressLine line(ctx.err, o.what, o.progress, o.progress_tty);
  std::unique_ptr<grpc::ClientContext> call = ctx.client.StreamContext();
  std::unique_ptr<grpc::ClientReader<v1::ExportChunk>> reader =
      ctx.client.data().Export(call.get(), request);
  v1::ExportChunk chunk;
  std::uint64_t received = 0;
  std::optional<v1::ExportReport> report;
  std::string stage = "waiting";
  double fraction = 0;
  while (reader->Read(&chunk)) {
    if (chunk.has_progress()) {
      stage = chunk.progress().stage();
      fraction = chunk.progress().fraction();
      line.Update(stage, fraction, received);
    } else if (chunk.has_data()) {
      if (chunk.data().offset() != received) {
        call->TryCancel();
        line.Finish();
        ctx.err << "brdfctl export: the daemon sent bytes at offset " << chunk.data().offset()
                << " after " << received << " bytes; try again\n";
        return fail(kExitFailure);
      }
      out.write(chunk.data().content().data(),
                static_cast<std::streamsize>(chunk.data().content().size()));
      if (!out) {
        call->TryCancel();
        line.Finish();
        ctx.err << "brdfctl export: writing " << (to_stdout ? "standard output" : partial)
                << " failed (disk full?)\n";
        return fail(kExitFailure);
      }
      received += chunk.data().content().size();
      line.Update(stage, fraction, received);
    } else if (chunk.has_report()) {
      report = chunk.report();
    }
  }
  line.Finish();
  const grpc::Status status = reader->Finish();
  if (!status.ok()) {
    fail(0);
    return ReportRpcError(ctx.err, status, "Export", ctx.client.options().address);
  }
  if (!report || report->bytes() != received) {
    ctx.err << "brdfctl export: the stream ended "
            << (report ? "with a byte count" : "without a report") << " that does not match the "
            << received << " bytes received; try again\n";
    return fail(kExitFailure);
  }
  const std::string path = to_stdout          ? "standard output"
                           : o.output.empty() ? report->file_name()
                                              : o.output;
  if (!to_stdout) {
    file.close();
    if (!file || std::rename(partial.c_str(), path.c_str()) != 0) {
      ctx.err << "brdfctl export: cannot move " << partial << " to " << path << "\n";
      return fail(kExitFailure);
    }
    if (!report->description_json().empty()) {
      std::ofstream json(path + ".json", std::ios::trunc);
      json << report->description_json();
      if (!json) {
        ctx.err << "brdfctl export: cannot write " << path << ".json\n";
        return kExitFailure;
      }
    }
  } else {
    ctx.out.flush();
  }
  for (const std::string& w : report->warnings())
    ctx.err << "brdfctl export: warning: " << w << "\n";
  if (ctx.json) {
    PrintJsonLine(to_stdout ? ctx.err : ctx.out, *report);
  } else {
    PrintReport(ctx.err, *report, path);
  }
  return kExitOk;
}

}  // namespace brdf::ctl
