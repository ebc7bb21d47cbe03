#include "tools/brdf-export/export_commands.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <system_error>

#include "core/analytic_brdf.h"
#include "core/export/fill/chain.h"
#include "core/export/fill/session_interpolant.h"
#include "core/export/fill/uncertain_grid.h"
#include "core/export/grid/npy_writer.h"
#include "core/export/grid/regular_grid.h"
#include "core/export/grid/text.h"
#include "core/export/merl/reader.h"
#include "core/export/merl/writer.h"
#include "core/export/number_text.h"
#include "core/export/readings_csv.h"
#include "core/export/readings_csv_reader.h"
#include "core/export/rgl/writer.h"
#include "core/export/synthetic_session.h"
#include "core/fit/fit.h"
#include "core/fit/fit_report.h"
#include "core/fit/models.h"
#include "core/geometry.h"
#include "core/uncertainty/budget.h"
#include "data/cie_tables.h"
#include "storage/session_readings.h"
#include "storage/session_store.h"
#include "tools/brdf-export/output_file.h"
#include "tools/brdf-export/progress_line.h"

namespace brdf::export_tool {
namespace {

int Fail(std::ostream& err, const char* command, const Status& st) {
  err << "brdf-export " << command << ": " << st.ToString() << "\n";
  switch (st.code()) {
    case StatusCode::kInvalidArgument:
    case StatusCode::kNotFound:
    case StatusCode::kFailedPrecondition:
      return kExitInvalid;
    default:
      return kExitFailure;
  }
}

// Opens an EXISTING brdfd database (kNotFound naming the path when there is no file: the store
// itself would create an empty one).
Result<std::unique_ptr<storage::SessionStore>> OpenExistingStore(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return NotFound("no database at " + path +
                    ": give the brdfd database file (the daemon's [storage] database setting, "
                    "/var/lib/brdfd/brdfd.db by default)");
  }
  return storage::SessionStore::Open(path);
}

// An export runs without a deadline of its own; the CancelToken is there for API symmetry with
// the daemon's handlers (Ctrl-C ends the process, and the .partial file is removed on exit paths).
CallContext RunContext() {
  return CallContext::WithTimeout(std::chrono::hours(24 * 365));
}

Result<exports::Session> LoadInput(const CommonOptions& c) {
  if (c.demo) {
    if (!c.db_path.empty()) return InvalidArgument("give either --demo or --db, not both");
    return exports::SyntheticSession(AnalyticBrdf::PaintLike());
  }
  if (c.db_path.empty()) {
    return InvalidArgument(
        "no database: give --db PATH --session N (or --demo for a synthetic "
        "session)");
  }
  if (c.session_id < 0) return InvalidArgument("no session: give --session N");
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<storage::SessionStore> store, OpenExistingStore(c.db_path));
  return storage::LoadSessionReadings(*store, c.session_id);
}

Result<std::vector<double>> ParseNumbers(const std::string& text, const char* what) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      return InvalidArgument(std::string(what) + ": '" + item + "' in '" + text +
                             "' is not a number");
    }
  }
  return out;
}

using Interpolation = exports::SessionInterpolant;

// The fill chain's stages, on stderr.
void DescribeFillChain(const Interpolation& in, std::ostream& err) {
  if (!in.model) return;
  err << "brdf-export: fill chain: " << interp::MethodName(in.method)
      << (in.fallback ? ", then delaunay" : "") << ", then Cook-Torrance (relative RMS "
      << in.model->overall.relative_rms << " over " << in.derived->samples.size() << " readings)\n";
}

Result<Interpolation> BuildInterpolator(const exports::Session& session, exports::Quantity q,
                                        const CommonOptions& c, const InterpChoice& choice,
                                        std::ostream& err) {
  BRDF_ASSIGN_OR_RETURN(interp::Method method, interp::ParseMethod(choice.method));
  BRDF_ASSIGN_OR_RETURN(exports::FillPolicy policy, exports::ParseFillPolicy(choice.fill));
  BRDF_ASSIGN_OR_RETURN(interp::Coordinates coordinates,
                        interp::ParseCoordinates(choice.coordinates));
  Result<interp::Trend> trend = interp::ParseTrend(choice.trend);
  if (!trend.ok()) return trend.status().WithContext("--trend");
  interp::Options options;
  options.coordinates = coordinates;
  options.trend = *trend;
  options.mirror_phi = choice.mirror_phi;
  options.reciprocity = choice.reciprocity;
  if (!choice.scale.empty()) {
    BRDF_ASSIGN_OR_RETURN(std::vector<double> scale, ParseNumbers(choice.scale, "--scale"));
    options.axis_scale = scale;
  }
  if (exports::HasSeveralDialPositions(session)) {
    err << "brdf-export: warning: session " << session.id
        << " was measured at several dial positions γ (anisotropic); this export uses the "
           "isotropic reduction (θi, θo, φ) and folds them together\n";
  }
  BRDF_ASSIGN_OR_RETURN(exports::DerivedSamples derived,
                        exports::DeriveSamples(session, q, {c.exclude_flagged}));
  if (!derived.skipped.empty()) {
    err << "brdf-export: " << derived.skipped.size()
        << " sample readings left out; the first: " << derived.skipped.front().reason << "\n";
  }
  BRDF_ASSIGN_OR_RETURN(
      Interpolation in,
      exports::BuildSessionInterpolant(std::move(derived), method, options, policy, RunContext()));
  DescribeFillChain(in, err);
  return in;
}

exports::RunControl Control(const CommonOptions& c, ProgressLine* line) {
  exports::RunControl control;
  control.threads = c.threads;
  if (line != nullptr) control.progress = [line](double f) { line->Update(f); };
  return control;
}

bool StderrIsTerminal() {
  return isatty(STDERR_FILENO) == 1;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// `output`'s uncertainty arrays: their names for the sidecar (exports::UncertaintyFiles of the
// file's name) and where they are written (beside it).
std::vector<std::pair<exports::UncertaintyFile, std::string>> UncertaintyPaths(
    const std::string& output) {
  const std::filesystem::path path(output);
  std::vector<std::pair<exports::UncertaintyFile, std::string>> out;
  for (exports::UncertaintyFile& f : exports::UncertaintyFiles(path.filename().string())) {
    std::string where = (path.parent_path() / f.file_name).string();
    out.emplace_back(std::move(f), std::move(where));
  }
  return out;
}

// The grid resampled to `values`; with --uncertainty in the same pass as the daemon's export
// (fill/uncertain_grid.h), the three arrays written and committed beside `output`. The report,
// the chain's tally and (with --uncertainty) the sidecar's "uncertainty" object and warnings.
Result<exports::UncertainGrid> Resample(const Interpolation& in, const exports::RegularGrid& grid,
                                        exports::Quantity q, const GridOptions& o,
                                        const exports::RunControl& control,
                                        exports::GridSink& values, const std::string& output) {
  exports::UncertainGrid out;
  if (!o.uncertainty) {
    BRDF_ASSIGN_OR_RETURN(
        out.report, exports::ResampleOnGrid(in.chain->Source(), grid, in.derived->grid, control,
                                            RunContext(), values));
    out.tally = in.chain->Tally();
    return out;
  }
  const exports::NpyType type = o.float32 ? exports::NpyType::kFloat32 : exports::NpyType::kFloat64;
  std::vector<std::unique_ptr<OutputFile>> files;
  std::vector<std::unique_ptr<exports::NpyGridWriter>> writers;
  std::array<exports::GridSink*, 3> sinks{};
  for (const auto& [file, where] : UncertaintyPaths(output)) {
    BRDF_ASSIGN_OR_RETURN(std::unique_ptr<OutputFile> opened, OutputFile::Open(where));
    files.push_back(std::move(opened));
    writers.push_back(std::make_unique<exports::NpyGridWriter>(files.back()->stream(), type));
    sinks[writers.size() - 1] = writers.back().get();
  }
  BRDF_ASSIGN_OR_RETURN(
      out, exports::ResampleWithUncertainty(in, grid, q, control, RunContext(), values, sinks,
                                            std::filesystem::path(output).filename().string()));
  for (const std::unique_ptr<OutputFile>& f : files) BRDF_RETURN_IF_ERROR(f->Commit());
  return out;
}

}  // namespace

int RunCsv(const CommonOptions& c, const CsvOptions& o, std::ostream& err) {
  Result<exports::Quantity> q = exports::ParseQuantity(o.quantity);
  if (!q.ok()) return Fail(err, "csv", q.status());
  Result<exports::Session> session = LoadInput(c);
  if (!session.ok()) return Fail(err, "csv", session.status());
  Result<std::unique_ptr<OutputFile>> file = OutputFile::Open(c.output);
  if (!file.ok()) return Fail(err, "csv", file.status());
  Result<exports::ReadingsCsvReport> report =
      exports::WriteReadingsCsv(*session, *q, (*file)->stream(), {c.exclude_flagged});
  if (!report.ok()) return Fail(err, "csv", report.status());
  if (Status st = (*file)->Commit(); !st.ok()) return Fail(err, "csv", st);
  err << "brdf-export csv: session " << session->id << ", " << report->rows << " rows ("
      << exports::QuantityName(*q) << "), " << report->skipped.size()
      << " sample readings left out → " << c.output << "\n";
  return kExitOk;
}

namespace {

// The grid's file format, "npy" or "csv" (--format, else from -o's name), with the options that
// need .npy checked against it.
Result<std::string> GridFormat(const CommonOptions& c, const GridOptions& o) {
  std::string format = o.format;
  if (format.empty()) format = EndsWith(c.output, ".csv") ? "csv" : "npy";
  if (format != "npy" && format != "csv") {
    return InvalidArgument("--format '" + format + "': use npy or csv");
  }
  if (o.float32 && format != "npy") {
    return InvalidArgument("--float32 is for .npy grids, not CSV");
  }
  if (format == "npy" && c.output == "-") {
    return InvalidArgument("an .npy grid needs a file: give -o PATH.npy");
  }
  if (o.uncertainty && format != "npy") {
    return InvalidArgument(
        "--uncertainty is for .npy grids: a grid as CSV has no room for the arrays (export it as "
        ".npy, or leave --uncertainty out)");
  }
  return format;
}

}  // namespace

int RunGrid(const CommonOptions& c, const GridOptions& o, std::ostream& err) {
  Result<exports::Quantity> q = exports::ParseQuantity(o.quantity);
  if (!q.ok()) return Fail(err, "grid", q.status());
  Result<std::vector<double>> steps = ParseNumbers(o.steps, "--steps");
  if (!steps.ok()) return Fail(err, "grid", steps.status());
  if (steps->size() == 1) steps->resize(3, steps->front());
  if (steps->size() != 3) {
    return Fail(err, "grid",
                InvalidArgument("--steps '" + o.steps +
                                "': give dθi,dθo,dφ in degrees (three values) or one for all"));
  }
  Result<exports::RegularGrid> grid = exports::MakeRegularGrid(
      (*steps)[0], (*steps)[1], (*steps)[2],
      o.nodes ? exports::GridPlacement::kNodes : exports::GridPlacement::kCellCentres);
  if (!grid.ok()) return Fail(err, "grid", grid.status());
  Result<std::string> format_or = GridFormat(c, o);
  if (!format_or.ok()) return Fail(err, "grid", format_or.status());
  const std::string format = *format_or;
  Result<exports::Session> session = LoadInput(c);
  if (!session.ok()) return Fail(err, "grid", session.status());
  Result<Interpolation> in = BuildInterpolator(*session, *q, c, o.interp, err);
  if (!in.ok()) return Fail(err, "grid", in.status());

  const WavelengthGrid bands = in->derived->grid;
  const double bytes =
      static_cast<double>(grid->cells()) * static_cast<double>(bands.count) * (o.float32 ? 4 : 8);
  err << "brdf-export grid: " << grid->theta_i.count << " × " << grid->theta_o.count << " × "
      << grid->phi.count << " cells × " << bands.count << " bands ("
      << (format == "npy" ? "" : "at least ") << bytes / 1e6 << " MB) by " << o.interp.method
      << " on " << exports::ResolveThreads(c.threads) << " threads\n";

  Result<std::unique_ptr<OutputFile>> file = OutputFile::Open(c.output);
  if (!file.ok()) return Fail(err, "grid", file.status());
  const exports::GridExportInfo info{session->id,
                                     session->name,
                                     *q,
                                     o.interp.method,
                                     in->derived->samples.size(),
                                     in->derived->skipped.size(),
                                     o.float32 ? "float32" : "float64"};
  exports::NpyGridWriter npy((*file)->stream(),
                             o.float32 ? exports::NpyType::kFloat32 : exports::NpyType::kFloat64);
  exports::CsvGridWriter csv((*file)->stream(), info);
  exports::GridSink& sink = format == "npy" ? static_cast<exports::GridSink&>(npy) : csv;
  ProgressLine line(err, "brdf-export grid", StderrIsTerminal());
  Result<exports::UncertainGrid> u =
      Resample(*in, *grid, *q, o, Control(c, c.quiet ? nullptr : &line), sink, c.output);
  line.Finish();
  if (!u.ok()) return Fail(err, "grid", u.status());
  if (Status st = (*file)->Commit(); !st.ok()) return Fail(err, "grid", st);
  if (format == "npy") {
    Result<std::unique_ptr<OutputFile>> json = OutputFile::Open(c.output + ".json");
    if (!json.ok()) return Fail(err, "grid", json.status());
    exports::InterpolantInfo how = in->Info();
    how.fill_json = u->tally.Json();
    (*json)->stream() << exports::GridDescriptionJson(*grid, bands, info, u->report, how,
                                                      u->uncertainty_json);
    if (Status st = (*json)->Commit(); !st.ok()) return Fail(err, "grid", st);
  }
  for (const std::string& w : u->warnings) err << "brdf-export grid: warning: " << w << "\n";
  err << "brdf-export grid: fill " << u->tally.Summary() << "\n";
  err << "brdf-export grid: " << u->report.Summary() << " → " << c.output
      << (format == "npy" ? " (axes, wavelengths, units: " + c.output + ".json)" : "") << "\n";
  if (o.uncertainty) {
    for (const auto& [array, where] : UncertaintyPaths(c.output)) {
      err << "brdf-export grid: " << exports::UncertainPlaneName(array.plane) << " → " << where
          << "\n";
    }
  }
  return kExitOk;
}

int RunMerl(const CommonOptions& c, const MerlOptions& o, std::ostream& out, std::ostream& err) {
  std::vector<Directions> probes;
  for (const std::string& p : o.probes) {
    Result<std::vector<double>> v = ParseNumbers(p, "--probe");
    if (!v.ok()) return Fail(err, "merl", v.status());
    if (v->size() != 4) {
      return Fail(err, "merl", InvalidArgument("--probe '" + p + "': give θi,φi,θo,φo in degrees"));
    }
    probes.push_back({(*v)[0], (*v)[1], (*v)[2], (*v)[3]});
  }
  if (c.output == "-") {
    return Fail(err, "merl", InvalidArgument("a MERL .binary needs a file: give -o PATH.binary"));
  }
  Result<data::CieTables> cie = data::LoadCieTables(o.colord_dir);
  if (!cie.ok()) return Fail(err, "merl", cie.status());
  Result<exports::Session> session = LoadInput(c);
  if (!session.ok()) return Fail(err, "merl", session.status());
  Result<Interpolation> in =
      BuildInterpolator(*session, exports::Quantity::kBrdf, c, o.interp, err);
  if (!in.ok()) return Fail(err, "merl", in.status());
  const WavelengthGrid bands = in->derived->grid;
  Result<exports::SpectralRgbWeights> rgb =
      exports::SpectralRgbWeights::Make(bands, cie->d65, cie->cmf);
  if (!rgb.ok()) return Fail(err, "merl", rgb.status());

  err << "brdf-export merl: 90 × 90 × 180 cells by " << o.interp.method << " on "
      << exports::ResolveThreads(c.threads) << " threads, linear sRGB under D65\n";
  ProgressLine line(err, "brdf-export merl", StderrIsTerminal());
  const exports::SpectrumSource source = in->chain->Source();
  Result<exports::MerlExport> table = exports::BuildMerlTable(
      source, bands, *rgb, Control(c, c.quiet ? nullptr : &line), RunContext());
  line.Finish();
  if (!table.ok()) return Fail(err, "merl", table.status());
  Result<std::unique_ptr<OutputFile>> file = OutputFile::Open(c.output);
  if (!file.ok()) return Fail(err, "merl", file.status());
  if (Status st = exports::WriteMerl(table->table, (*file)->stream()); !st.ok()) {
    return Fail(err, "merl", st);
  }
  if (Status st = (*file)->Commit(); !st.ok()) return Fail(err, "merl", st);
  err << "brdf-export merl: fill " << in->chain->Tally().Summary() << "\n";
  err << "brdf-export merl: " << table->report.Summary() << " → " << c.output << "\n";

  if (!probes.empty()) {
    // What the interpolator gives at each probe (its spectrum's RGB) next to what a MERL reader
    // finds in the file there: tools/check/merl_read.py compares the file side independently.
    out << "theta_i,phi_i,theta_o,phi_o,status,interp_r,interp_g,interp_b,merl_r,merl_g,merl_b\n";
    std::vector<double> spectrum(bands.count);
    for (const Directions& d : probes) {
      const interp::InterpStatus st = source(ToIsotropic(d), spectrum);
      const Rgb merl = exports::LookupMerl(table->table, d);
      using exports::FormatNumber;
      out << FormatNumber(d.theta_i) << ',' << FormatNumber(d.phi_i) << ','
          << FormatNumber(d.theta_o) << ',' << FormatNumber(d.phi_o) << ','
          << interp::InterpStatusName(st);
      if (st == interp::InterpStatus::kOk) {
        const Rgb v = rgb->Apply(spectrum);
        out << ',' << FormatNumber(v.r) << ',' << FormatNumber(v.g) << ',' << FormatNumber(v.b);
      } else {
        out << ",,,";
      }
      out << ',' << FormatNumber(merl.r) << ',' << FormatNumber(merl.g) << ','
          << FormatNumber(merl.b) << "\n";
    }
  }
  return kExitOk;
}

int RunRgl(const CommonOptions& c, const RglCommandOptions& o, std::ostream& err) {
  if (c.output == "-") {
    return Fail(err, "rgl", InvalidArgument("an RGL .bsdf needs a file: give -o PATH.bsdf"));
  }
  Result<exports::Session> session = LoadInput(c);
  if (!session.ok()) return Fail(err, "rgl", session.status());
  Result<Interpolation> in =
      BuildInterpolator(*session, exports::Quantity::kBrdf, c, o.interp, err);
  if (!in.ok()) return Fail(err, "rgl", in.status());
  exports::SessionRglOptions options;
  options.theta_i_count = o.theta_i_count;
  options.sample_res = o.sample_res;
  if (o.rgb) {
    Result<data::CieTables> cie = data::LoadCieTables(o.colord_dir);
    if (!cie.ok()) return Fail(err, "rgl", cie.status());
    Result<exports::SpectralRgbWeights> rgb =
        exports::SpectralRgbWeights::Make(in->derived->grid, cie->d65, cie->cmf);
    if (!rgb.ok()) return Fail(err, "rgl", rgb.status());
    options.rgb = *rgb;
  }
  err << "brdf-export rgl: " << options.theta_i_count << " θi slices × " << options.sample_res
      << "² nodes by " << o.interp.method << (o.rgb ? ", RGB" : ", spectral") << "\n";
  ProgressLine line(err, "brdf-export rgl", StderrIsTerminal());
  Result<exports::RglExport> table = exports::BuildSessionRgl(
      *session, *in, options, Control(c, c.quiet ? nullptr : &line), RunContext());
  line.Finish();
  if (!table.ok()) return Fail(err, "rgl", table.status());
  Result<std::unique_ptr<OutputFile>> file = OutputFile::Open(c.output);
  if (!file.ok()) return Fail(err, "rgl", file.status());
  if (Status st = exports::WriteRgl(table->fields, (*file)->stream()); !st.ok()) {
    return Fail(err, "rgl", st);
  }
  if (Status st = (*file)->Commit(); !st.ok()) return Fail(err, "rgl", st);
  err << "brdf-export rgl: fill " << in->chain->Tally().Summary() << "\n";
  err << "brdf-export rgl: " << table->report.Summary() << " → " << c.output << "\n";
  return kExitOk;
}

namespace {

// What a fit runs on: the observations and what the report says of them.
struct FitInput {
  fit::Observations data;
  fit::FitReportInfo info;
};

// A budget component's shared source for the fit: the component and what it is shared through
// ("reference_signal via reference_reading 812"); the same name in two readings is one error.
std::string SharedSourceName(const uncertainty::Component& c) {
  return c.name + " via " + uncertainty::SharingName(c.shared.kind) + " " +
         std::to_string(c.shared.id);
}

// The stored budgets of a session's sample readings (of the BRDF), by reading id; none for the
// demo session.
Result<std::map<std::int64_t, uncertainty::ReadingBudget>> SampleBudgets(const CommonOptions& c) {
  std::map<std::int64_t, uncertainty::ReadingBudget> budgets;
  if (c.demo) return budgets;
  BRDF_ASSIGN_OR_RETURN(std::unique_ptr<storage::SessionStore> store, OpenExistingStore(c.db_path));
  constexpr int kPage = 1000;
  for (std::int64_t after = 0;;) {
    BRDF_ASSIGN_OR_RETURN(std::vector<storage::ReadingRecord> page,
                          store->GetReadings(c.session_id, after, kPage));
    for (storage::ReadingRecord& r : page) {
      if (r.uncertainty.has_value() && r.uncertainty->quantity == Quantity::kBrdf) {
        budgets.emplace(r.id, std::move(*r.uncertainty));
      }
    }
    if (page.size() < static_cast<std::size_t>(kPage)) break;
    after = page.back().id;
  }
  return budgets;
}

// One sample reading for the fit: with its budget's independent part and shared components
// (generalised least squares) when its budget matches the derived BRDF's u, else with that u.
Status AddFitReading(fit::Observations& data, const exports::DerivedSample& s,
                     const uncertainty::ReadingBudget* budget) {
  if (budget == nullptr || s.u.empty() || budget->combined.size() != s.u.size() ||
      budget->independent.size() != s.u.size()) {
    return data.Add(s.iso, s.values, s.u);
  }
  std::vector<fit::SharedContribution> shared;
  for (const uncertainty::Component& c : budget->components) {
    if (c.shared.kind == uncertainty::Sharing::kIndependent) continue;
    shared.push_back({SharedSourceName(c), c.contribution});
  }
  return data.AddWithSharedTerms(s.iso, s.values, budget->independent, shared);
}

// The BRDF of a stored (or the demo) session's sample readings, with their budgets: the
// independent part and the shared components of each (the fit's generalised least squares).
Result<FitInput> FitInputFromSession(const CommonOptions& c, std::ostream& err) {
  BRDF_ASSIGN_OR_RETURN(const exports::Session session, LoadInput(c));
  if (exports::HasSeveralDialPositions(session)) {
    err << "brdf-export: warning: session " << session.id
        << " was measured at several dial positions γ; the models are isotropic\n";
  }
  BRDF_ASSIGN_OR_RETURN(
      const exports::DerivedSamples derived,
      exports::DeriveSamples(session, exports::Quantity::kBrdf, {c.exclude_flagged}));
  BRDF_ASSIGN_OR_RETURN(const auto budgets, SampleBudgets(c));
  FitInput in{fit::Observations(derived.grid), {session.id, session.name, 0, 0, 0}};
  for (const exports::DerivedSample& s : derived.samples) {
    const auto b = budgets.find(s.reading_id);
    BRDF_RETURN_IF_ERROR(AddFitReading(in.data, s, b == budgets.end() ? nullptr : &b->second)
                             .WithContext("reading " + std::to_string(s.reading_id)));
  }
  in.info.left_out = derived.skipped.size();
  return in;
}

// The sample rows of a readings CSV of the BRDF, with their u_<λ> columns when present.
Result<FitInput> FitInputFromCsv(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return NotFound("cannot open the readings CSV " + path);
  std::stringstream text;
  text << file.rdbuf();
  BRDF_ASSIGN_OR_RETURN(const exports::ReadingsCsv csv,
                        exports::ParseReadingsCsv(text.str(), path));
  if (csv.quantity != "brdf") {
    return InvalidArgument(path + " holds " + (csv.quantity.empty() ? "no named" : csv.quantity) +
                           " quantity; the fit needs the BRDF: export with --quantity brdf");
  }
  FitInput in{fit::Observations(csv.grid), {csv.session_id, csv.session_name, 0, 0, 0}};
  for (const exports::ReadingsCsvRow& row : csv.rows) {
    if (!row.kind.empty() && row.kind != "sample") continue;
    BRDF_RETURN_IF_ERROR(in.data.Add(ToIsotropic(row.directions), row.values, row.u)
                             .WithContext(path + ", reading " + std::to_string(row.id)));
  }
  if (in.data.size() == 0) return FailedPrecondition(path + " has no sample readings");
  return in;
}

}  // namespace

int RunFit(const CommonOptions& c, const FitCommandOptions& o, std::ostream& err) {
  const bool lambert = o.model == "lambert" || o.model == "both";
  const bool ct = o.model == "cook-torrance" || o.model == "both";
  if (!lambert && !ct) {
    return Fail(err, "fit",
                InvalidArgument("--model '" + o.model + "': use lambert, cook-torrance or both"));
  }
  if (!o.readings_csv.empty() && (c.demo || !c.db_path.empty())) {
    return Fail(err, "fit", InvalidArgument("give either --readings or --db/--demo, not both"));
  }
  Result<FitInput> input =
      o.readings_csv.empty() ? FitInputFromSession(c, err) : FitInputFromCsv(o.readings_csv);
  if (!input.ok()) return Fail(err, "fit", input.status());
  const fit::Observations& data = input->data;
  input->info.observations = data.size();
  input->info.with_uncertainty = data.with_uncertainty();
  std::optional<fit::LambertFit> lambert_fit;
  std::optional<fit::CookTorranceFit> ct_fit;
  if (lambert) {
    Result<fit::LambertFit> r = fit::FitLambert(data);
    if (!r.ok()) return Fail(err, "fit", r.status());
    lambert_fit = std::move(*r);
  }
  if (ct) {
    fit::CookTorranceOptions options;
    options.sharing =
        o.per_band ? fit::ParameterSharing::kPerBand : fit::ParameterSharing::kSharedAcrossBands;
    ProgressLine line(err, "brdf-export fit", StderrIsTerminal());
    if (!c.quiet) options.progress = [&line](double f) { line.Update(f); };
    Result<fit::CookTorranceFit> r = fit::FitCookTorrance(data, options, RunContext());
    line.Finish();
    if (!r.ok()) return Fail(err, "fit", r.status());
    ct_fit = std::move(*r);
  }
  Result<std::unique_ptr<OutputFile>> file = OutputFile::Open(c.output);
  if (!file.ok()) return Fail(err, "fit", file.status());
  const fit::LambertFit* l = lambert_fit ? &*lambert_fit : nullptr;
  const fit::CookTorranceFit* t = ct_fit ? &*ct_fit : nullptr;
  (*file)->stream() << fit::FitReportCsv(input->info, l, t);
  if (Status st = (*file)->Commit(); !st.ok()) return Fail(err, "fit", st);
  err << "brdf-export fit: session " << input->info.session_id << ", " << data.size()
      << " BRDF readings (" << input->info.left_out << " left out; "
      << (data.weighted()
              ? "weighted by their uncertainties: " +
                    fit::WeightingText(data.weighting(), data.shared_sources().size())
              : std::to_string(data.with_uncertainty()) + " with an uncertainty: unweighted")
      << ") → " << c.output << "\n"
      << fit::FitSummary(l, t);
  return kExitOk;
}

}  // namespace brdf::export_tool
