#include "tools/brdfctl/commands/export.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "tools/brdfctl/commands/export_stream.h"
#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/rpc_error.h"

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

// True for the exports that interpolate (grid, merl, rgl); csv and bird write the readings.
bool Interpolates(const ExportOptions& o) {
  return o.what != "csv" && o.what != "bird";
}

// The request's format from `what` (and, for a grid, --format or the output's extension).
int SetFormat(const ExportOptions& o, std::ostream& err, v1::ExportRequest* request) {
  if (o.what == "csv") {
    request->set_format(v1::EXPORT_FORMAT_READINGS_CSV);
  } else if (o.what == "grid") {
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
  } else if (o.what == "bird") {
    request->set_format(v1::EXPORT_FORMAT_BIRD_JSON);
  } else {
    return Invalid(err, "'" + o.what + "': export csv, grid, merl, rgl or bird");
  }
  return kExitOk;
}

// The quantity, the RGL flags and the fill policy, each refused where the format has no use
// for it.
int SetQuantityAndFill(const ExportOptions& o, std::ostream& err, v1::ExportRequest* request) {
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
  if ((o.what == "merl" || rgl || o.what == "bird") && o.quantity != "brdf") {
    const char* file = rgl ? "an RGL" : o.what == "bird" ? "a BiRD" : "a MERL";
    return Invalid(err, std::string(file) + " file holds the BRDF: leave out --quantity");
  }
  if (!rgl && (o.rgb || o.theta_i_count != 0 || o.resolution != 0)) {
    return Invalid(err, "--rgb, --theta-i and --resolution are for rgl exports");
  }
  if (o.float32 && request->format() != v1::EXPORT_FORMAT_GRID_NPY) {
    return Invalid(err, "--float32 is for grid exports to .npy");
  }
  request->set_float32(o.float32);
  if (o.uncertainty && request->format() != v1::EXPORT_FORMAT_GRID_NPY &&
      request->format() != v1::EXPORT_FORMAT_MERL_BINARY &&
      request->format() != v1::EXPORT_FORMAT_RGL_BSDF) {
    return Invalid(err,
                   "--uncertainty is for grid exports to .npy, merl and rgl (the readings CSV "
                   "has u_<λ> columns and the BiRD file uBRDF always)");
  }
  request->set_include_uncertainty(o.uncertainty);
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
  if (!Interpolates(o) && o.fill != "chain") {
    return Invalid(err, "--fill is for grid, merl and rgl exports");
  }
  return kExitOk;
}

// The interpolation: method, coordinates, trend, axis scale, mirrored and swapped readings.
int SetInterpolation(const ExportOptions& o, std::ostream& err, v1::ExportRequest* request) {
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
  if (!Interpolates(o) && coordinates != v1::INTERPOLATION_COORDINATES_INCIDENCE) {
    return Invalid(err, "--coordinates is for grid, merl and rgl exports");
  }
  options->set_coordinates(coordinates);
  v1::InterpolationTrend trend{};
  if (!ParseTrendName(o.trend, &trend)) {
    return Invalid(err, "--trend '" + o.trend + "': use none or bivariate");
  }
  if (!Interpolates(o) && trend != v1::INTERPOLATION_TREND_NONE) {
    return Invalid(err, "--trend is for grid, merl and rgl exports");
  }
  options->set_trend(trend);
  for (double s : o.axis_scale) options->add_axis_scale(s);
  options->set_mirror_phi(o.mirror_phi);
  // A MERL or RGL cell stands for a pair of directions and its swap alike (as brdf-export).
  const bool swapped_by_default = o.what == "merl" || o.what == "rgl";
  options->set_reciprocity(swapped_by_default ? !o.no_reciprocity : o.reciprocity);
  return kExitOk;
}

// The request for the options, or an exit status and message for a bad option.
// ExportRequest.chunk_bytes' largest: 4 MiB − 1 KiB (brdfctl reads messages up to 64 MiB).
constexpr std::uint32_t kLargestExportChunk = 4 * 1024 * 1024 - 1024;

int BuildRequest(const ExportOptions& o, std::ostream& err, v1::ExportRequest* request) {
  request->set_session_id(o.session_id);
  if (int rc = SetFormat(o, err, request); rc != kExitOk) return rc;
  if (int rc = SetQuantityAndFill(o, err, request); rc != kExitOk) return rc;
  if (int rc = SetInterpolation(o, err, request); rc != kExitOk) return rc;
  if (!o.steps.empty()) {
    if (o.what != "grid") return Invalid(err, "--steps is for grid exports");
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
  // The largest chunks brdfd sends (brdf.proto): about a 32nd of the messages of its 128 KiB
  // default; brdfctl reads as the chunks come, so brdfd never waits on it holding one.
  request->set_chunk_bytes(kLargestExportChunk);
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

// Where part `p` of the report goes beside `path`: PATH's stem, ".<name>", and the extension of
// the daemon's name for it ("x.npy", u → "x.u.npy"; "x.binary", uncertainty →
// "x.uncertainty.json").
std::string PartPath(const std::string& path, const v1::ExportPart& p) {
  const auto extension_of = [](const std::string& name) {
    const std::size_t slash = name.rfind('/');
    const std::size_t dot = name.rfind('.');
    return dot == std::string::npos || (slash != std::string::npos && dot < slash)
               ? std::string()
               : name.substr(dot);
  };
  const std::string ext = extension_of(path);
  return path.substr(0, path.size() - ext.size()) + "." + p.name() + extension_of(p.file_name());
}

std::string BaseName(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

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
  for (const v1::ExportPart& p : r.parts()) {
    err << "brdfctl export: " << p.name() << " → " << PartPath(path, p) << " (" << p.bytes()
        << " bytes)\n";
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

// Where the bytes go until the report names the file: FILE.partial, renamed when kept and
// removed when discarded, or standard output.
class ExportDestination {
 public:
  ExportDestination(std::ostream& standard_output, std::string partial, bool to_stdout)
      : standard_output_(standard_output), partial_(std::move(partial)), to_stdout_(to_stdout) {}

  bool Open() { return to_stdout_ || file_.Open(partial_); }
  // Appends the pieces; false when the write fails.
  bool Write(const std::vector<std::string_view>& pieces) {
    if (!to_stdout_) return file_.Write(pieces);
    for (std::string_view p : pieces) {
      standard_output_.write(p.data(), static_cast<std::streamsize>(p.size()));
    }
    return static_cast<bool>(standard_output_);
  }
  // For messages: "standard output" or the .partial file.
  std::string name() const { return to_stdout_ ? "standard output" : partial_; }
  const std::string& partial() const { return partial_; }
  bool to_stdout() const { return to_stdout_; }

  void Discard() {
    if (to_stdout_) return;
    file_.Close();
    std::remove(partial_.c_str());
  }
  // Closes the file and renames it to `path`; false (the .partial file left) when either fails.
  bool Keep(const std::string& path) {
    return file_.Close() && std::rename(partial_.c_str(), path.c_str()) == 0;
  }

 private:
  std::ostream& standard_output_;
  std::string partial_;
  bool to_stdout_;
  ExportFile file_;  // written from the received messages (export_stream.h)
};

// A companion part of the export (ExportData.part, with --uncertainty): PARTIAL.<part>, renamed
// beside the file once the report has come.
struct PartFile {
  std::string partial;
  ExportFile file;
  std::uint64_t bytes = 0;
};

struct Received {
  std::uint64_t bytes = 0;
  std::optional<v1::ExportReport> report;
  std::map<std::string, PartFile> parts;
};

// Writes a chunk of a companion part at the offset expected; false (the message printed) when
// the offset, the part's file or the write is wrong.
bool WritePartChunk(CommandContext& ctx, const ExportMessage& data,
                    const ExportDestination& destination, Received* received) {
  PartFile& part = received->parts[data.part];
  if (part.partial.empty()) {
    part.partial = destination.partial() + "." + data.part;
    part.file.Open(part.partial);
  }
  if (data.offset != part.bytes || !part.file.ok()) {
    ctx.err << "brdfctl export: part '" << data.part
            << "': " << (part.file.ok() ? "bytes out of order" : "cannot create " + part.partial)
            << "; try again\n";
    return false;
  }
  part.bytes += data.content_size;
  if (!part.file.Write(data.content)) {
    ctx.err << "brdfctl export: writing " << part.partial << " failed (disk full?)\n";
    return false;
  }
  return true;
}

// Writes a data chunk at the offset expected; false (the message printed) when the offset or
// the write is wrong.
bool WriteChunk(CommandContext& ctx, const ExportMessage& data, ExportDestination& destination,
                std::uint64_t received) {
  if (data.offset != received) {
    ctx.err << "brdfctl export: the daemon sent bytes at offset " << data.offset << " after "
            << received << " bytes; try again\n";
    return false;
  }
  if (!destination.Write(data.content)) {
    ctx.err << "brdfctl export: writing " << destination.name() << " failed (disk full?)\n";
    return false;
  }
  return true;
}

// Reads the Export stream into `destination`, drawing the progress line. kExitOk once the report
// has come and its byte count matches; else the exit status, the problem printed.
int ReceiveExport(CommandContext& ctx, const ExportOptions& o, const v1::ExportRequest& request,
                  ExportDestination& destination, Received* received) {
  ExportProgressLine line(ctx.err, o.what, o.progress, o.progress_tty);
  std::unique_ptr<grpc::ClientContext> call = ctx.client.StreamContext();
  ExportStreamReader reader(ctx.client.channel(), call.get(), request);
  ExportMessage m;
  std::string stage = "waiting";
  double fraction = 0;
  while (reader.Read(&m)) {
    if (m.data && !m.part.empty()) {
      if (destination.to_stdout() || !WritePartChunk(ctx, m, destination, received)) {
        call->TryCancel();
        line.Finish();
        return kExitFailure;
      }
    } else if (m.data) {
      if (!WriteChunk(ctx, m, destination, received->bytes)) {
        call->TryCancel();
        line.Finish();
        return kExitFailure;
      }
      received->bytes += m.content_size;
      line.Update(stage, fraction, received->bytes);
    } else if (m.chunk.has_progress()) {
      stage = m.chunk.progress().stage();
      fraction = m.chunk.progress().fraction();
      line.Update(stage, fraction, received->bytes);
    } else if (m.chunk.has_report()) {
      received->report = m.chunk.report();
    }
  }
  line.Finish();
  if (reader.malformed()) {
    call->TryCancel();
    ctx.err << "brdfctl export: the daemon sent a message that is not an ExportChunk; is "
            << ctx.client.options().address << " brdfd?\n";
    return kExitFailure;
  }
  const grpc::Status status = reader.Finish();
  if (!status.ok()) {
    return ReportRpcError(ctx.err, status, "Export", ctx.client.options().address);
  }
  if (!received->report || received->report->bytes() != received->bytes) {
    ctx.err << "brdfctl export: the stream ended "
            << (received->report ? "with a byte count" : "without a report")
            << " that does not match the " << received->bytes << " bytes received; try again\n";
    return kExitFailure;
  }
  return kExitOk;
}

// Moves each companion part beside `path` (PartPath); false (the message printed) when one is
// missing, its size does not match the report's, or it cannot be moved.
bool KeepParts(std::ostream& err, const v1::ExportReport& report, const std::string& path,
               Received* received) {
  for (const v1::ExportPart& p : report.parts()) {
    PartFile& part = received->parts[p.name()];
    if (part.partial.empty() && p.bytes() == 0) continue;
    const std::string to = PartPath(path, p);
    if (part.bytes != p.bytes() || !part.file.Close() ||
        std::rename(part.partial.c_str(), to.c_str()) != 0) {
      err << "brdfctl export: part '" << p.name() << "' (" << part.bytes << " of " << p.bytes()
          << " bytes) could not be kept as " << to << "; try again\n";
      return false;
    }
  }
  return true;
}

// The description with the daemon's names of the parts replaced by the files' names beside
// `path`, so that it names what is on disk.
std::string DescriptionFor(const v1::ExportReport& report, const std::string& path) {
  std::string text = report.description_json();
  for (const v1::ExportPart& p : report.parts()) {
    const std::string from = "\"" + p.file_name() + "\"";
    const std::string to = "\"" + BaseName(PartPath(path, p)) + "\"";
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
      text.replace(at, from.size(), to);
      at += to.size();
    }
  }
  return text;
}

// The grid's description next to it (PATH.json), when the daemon sent one.
bool WriteDescription(std::ostream& err, const v1::ExportReport& report, const std::string& path) {
  if (report.description_json().empty()) return true;
  std::ofstream json(path + ".json", std::ios::trunc);
  json << DescriptionFor(report, path);
  if (!json) {
    err << "brdfctl export: cannot write " << path << ".json\n";
    return false;
  }
  return true;
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
  ExportDestination destination(
      ctx.out, (o.output.empty() ? "brdfctl-export-" + o.session_id : o.output) + ".partial",
      to_stdout);
  if (!destination.Open()) {
    return Invalid(ctx.err, "cannot create " + destination.partial() + ": check the directory");
  }
  Received received;
  if (int rc = ReceiveExport(ctx, o, request, destination, &received); rc != kExitOk) {
    destination.Discard();
    for (auto& [name, part] : received.parts) {
      part.file.Close();
      std::remove(part.partial.c_str());
    }
    return rc;
  }
  const v1::ExportReport& report = *received.report;
  const std::string path = to_stdout          ? "standard output"
                           : o.output.empty() ? report.file_name()
                                              : o.output;
  if (!to_stdout) {
    if (!destination.Keep(path)) {
      ctx.err << "brdfctl export: cannot move " << destination.partial() << " to " << path << "\n";
      destination.Discard();
      return kExitFailure;
    }
    if (!KeepParts(ctx.err, report, path, &received)) return kExitFailure;
    if (!WriteDescription(ctx.err, report, path)) return kExitFailure;
  } else {
    ctx.out.flush();
  }
  for (const std::string& w : report.warnings())
    ctx.err << "brdfctl export: warning: " << w << "\n";
  if (ctx.json) {
    PrintJsonLine(to_stdout ? ctx.err : ctx.out, report);
  } else {
    PrintReport(ctx.err, report, path);
  }
  return kExitOk;
}

namespace {

void AddFileFlags(CLI::App& cmd, ExportOptions& o) {
  cmd.add_option("what", o.what, "csv, grid, merl, rgl or bird (BiRD universal BRDF JSON)")
      ->required()
      ->check(CLI::IsMember({"csv", "grid", "merl", "rgl", "bird"}));
  cmd.add_option("-o,--output", o.output,
                 "the file (default: the daemon's name for it, e.g. "
                 "session-1-grid-brdf.npy); - for standard output (csv)");
  cmd.add_option("--quantity", o.quantity, "csv, grid: radiance, reflectance or brdf")
      ->capture_default_str();
  cmd.add_option("--format", o.format,
                 "grid: npy or csv (default: from the file's extension, else npy)");
  cmd.add_option("--steps", o.steps,
                 "grid: dθi,dθo,dφ in degrees, or one for all (default 1: 90 × 90 × 180 cells)")
      ->delimiter(',');
  cmd.add_flag("--nodes", o.nodes,
               "grid: nodes 0, step, …, 90 (180) instead of the cells' centres");
}

void AddInterpolationFlags(CLI::App& cmd, ExportOptions& o) {
  cmd.add_option("--method", o.method, "octant (the paper's), delaunay, nearest")
      ->capture_default_str();
  cmd.add_option("--scale", o.axis_scale, "per-axis distance multipliers a,b,c")->delimiter(',');
  cmd.add_flag("--mirror-phi", o.mirror_phi, "also use readings mirrored to −φ");
  cmd.add_option("--coordinates", o.coordinates,
                 "grid, merl, rgl: interpolate in incidence (θi, θo, φ) or half-diff "
                 "(Rusinkiewicz's half/difference angles) coordinates")
      ->check(CLI::IsMember({"incidence", "half-diff"}))
      ->capture_default_str();
  cmd.add_option("--trend", o.trend,
                 "grid, merl, rgl: none, or bivariate (blend the readings' residuals from a "
                 "fitted smooth f(θh, θd) and add it back)")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();
  cmd.add_flag("--reciprocity", o.reciprocity,
               "grid: also use readings with θi and θo swapped (merl, rgl: always, see below)");
  cmd.add_flag("--no-reciprocity", o.no_reciprocity,
               "merl, rgl: do not add the θi↔θo swapped readings");
  cmd.add_option("--fill", o.fill,
                 "grid, merl, rgl: cells the method cannot fill: chain (Delaunay, then the "
                 "fitted Cook-Torrance model) or none (NaN / −1)")
      ->check(CLI::IsMember({"chain", "none"}))
      ->capture_default_str();
}

void AddRglAndReadingFlags(CLI::App& cmd, ExportOptions& o, bool& no_progress) {
  cmd.add_flag("--rgb", o.rgb, "rgl: linear sRGB under D65 (field rgb) instead of spectra");
  cmd.add_flag("--uncertainty", o.uncertainty,
               "grid .npy: also FILE.u.npy, FILE.u_measurement.npy, FILE.u_interpolation.npy "
               "(standard uncertainties, k = 1, named in FILE.json); merl, rgl: "
               "FILE.uncertainty.json (the cells' u per band)");
  cmd.add_flag("--float32", o.float32,
               "grid .npy: float32 instead of float64, half the bytes (the .json says dtype)");
  cmd.add_option("--theta-i", o.theta_i_count, "rgl: θi slices (default 24)");
  cmd.add_option("--resolution", o.resolution,
                 "rgl: nodes per side of the warped square (default 48)");
  cmd.add_flag("--exclude-flagged", o.exclude_flagged,
               "leave out readings the quality policy flagged");
  cmd.add_flag("--no-progress", no_progress, "no progress line");
}

Runner AddExportOptions(CLI::App& cmd) {
  struct Args {
    ExportOptions options;
    bool no_progress = false;
  };
  auto args = std::make_shared<Args>();
  AddSessionId(cmd, args->options.session_id);
  AddFileFlags(cmd, args->options);
  AddInterpolationFlags(cmd, args->options);
  AddRglAndReadingFlags(cmd, args->options, args->no_progress);
  return OnDaemon([args](CommandContext& ctx) {
    ExportOptions options = args->options;
    options.progress = !args->no_progress;
    options.progress_tty = isatty(STDERR_FILENO) != 0;
    return RunExport(ctx, options);
  });
}

}  // namespace

void RegisterExportCommand(CommandRegistry& registry) {
  registry.Add({"export",
                "a session as a file: readings CSV, a regular grid (.npy or CSV), a MERL .binary, "
                "an RGL .bsdf, a BiRD universal BRDF JSON",
                "", AddExportOptions});
}

}  // namespace brdf::ctl
