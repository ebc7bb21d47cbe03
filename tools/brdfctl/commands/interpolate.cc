#include "tools/brdfctl/commands/interpolate.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <memory>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {
namespace {

std::string Cell(const std::string& text, std::size_t width) {
  std::string out = text;
  // Pad by code points (unit strings are UTF-8).
  std::size_t points = 0;
  for (unsigned char c : text) points += (c & 0xC0) != 0x80 ? 1 : 0;
  if (points < width) out += std::string(width - points, ' ');
  return out;
}

std::string QueryText(const v1::DirectionQuery& q) {
  return q.has_four() ? DirectionsText(q.four()) : IsoText(q.iso());
}

// The direction of a vertex, in the query's form; φ folded into [0, 180] for mirrored copies.
v1::DirectionQuery VertexQuery(const v1::InterpolationVertex& v) {
  v1::DirectionQuery q;
  if (v.coords_size() == 4) {
    v1::Directions* d = q.mutable_four();
    d->set_theta_i(v.coords(0));
    d->set_phi_i(v.coords(1));
    d->set_theta_o(v.coords(2));
    d->set_phi_o(v.coords(3));
  } else if (v.coords_size() == 3) {
    v1::IsoDirection* d = q.mutable_iso();
    d->set_theta_i(v.coords(0));
    d->set_theta_o(v.coords(1));
    d->set_phi(std::fabs(v.coords(2)));
  }
  return q;
}

std::string CoordsText(const v1::InterpolationVertex& v) {
  std::string out;
  for (int i = 0; i < v.coords_size(); ++i) out += Cell(Num(v.coords(i), 5), 9);
  return out;
}

bool ParseMethod(const std::string& name, v1::InterpolationMethod* method) {
  if (name == "octant")
    *method = v1::INTERPOLATION_METHOD_OCTANT;
  else if (name == "delaunay")
    *method = v1::INTERPOLATION_METHOD_DELAUNAY;
  else if (name == "nearest")
    *method = v1::INTERPOLATION_METHOD_NEAREST;
  else
    return false;
  return true;
}

bool ParseQuantity(const std::string& name, v1::Quantity* quantity) {
  if (name == "radiance")
    *quantity = v1::QUANTITY_RADIANCE;
  else if (name == "reflectance")
    *quantity = v1::QUANTITY_REFLECTANCE;
  else if (name == "brdf")
    *quantity = v1::QUANTITY_BRDF;
  else
    return false;
  return true;
}

// The request for the options; kExitInvalid (and a message) for a bad method, quantity,
// direction, coordinates or trend.
int BuildRequest(CommandContext& ctx, const InterpolateOptions& o,
                 v1::InterpolateRequest* request) {
  request->set_session_id(o.session_id);
  v1::InterpolationMethod method{};
  v1::Quantity quantity{};
  if (!ParseMethod(o.method, &method)) {
    ctx.err << "brdfctl: --method " << o.method << ": use octant, delaunay or nearest\n";
    return kExitInvalid;
  }
  if (!ParseQuantity(o.quantity, &quantity)) {
    ctx.err << "brdfctl: --quantity " << o.quantity << ": use radiance, reflectance or brdf\n";
    return kExitInvalid;
  }
  request->set_method(method);
  request->set_quantity(quantity);
  request->set_include_uncertainty(o.uncertainty);
  if (o.phi) {
    v1::IsoDirection* d = request->mutable_direction()->mutable_iso();
    d->set_theta_i(o.theta_i);
    d->set_theta_o(o.theta_o);
    d->set_phi(*o.phi);
  } else if (o.phi_i && o.phi_o) {
    v1::Directions* d = request->mutable_direction()->mutable_four();
    d->set_theta_i(o.theta_i);
    d->set_phi_i(*o.phi_i);
    d->set_theta_o(o.theta_o);
    d->set_phi_o(*o.phi_o);
  } else {
    ctx.err << "brdfctl: give --phi (isotropic: θi, θo, φ) or both --phi-i and --phi-o\n";
    return kExitInvalid;
  }
  v1::InterpolationOptions* options = request->mutable_options();
  v1::InterpolationCoordinates coordinates{};
  if (!ParseCoordinatesName(o.coordinates, &coordinates)) {
    ctx.err << "brdfctl: --coordinates " << o.coordinates << ": use incidence or half-diff\n";
    return kExitInvalid;
  }
  options->set_coordinates(coordinates);
  v1::InterpolationTrend trend{};
  if (!ParseTrendName(o.trend, &trend)) {
    ctx.err << "brdfctl: --trend " << o.trend << ": use none or bivariate\n";
    return kExitInvalid;
  }
  options->set_trend(trend);
  options->set_mirror_phi(o.mirror_phi);
  options->set_reciprocity(o.reciprocity);
  for (double s : o.axis_scale) options->add_axis_scale(s);
  return kExitOk;
}

// For --explain: each vertex's own spectrum (one InterpolateBatch call, nearest method, at the
// vertices' positions); none and a note when that call fails.
struct VertexSpectra {
  std::vector<v1::InterpolationResult> results;
  std::string note;
};

VertexSpectra FetchVertexSpectra(CommandContext& ctx, const v1::InterpolateRequest& request,
                                 const v1::InterpolationResult& result) {
  VertexSpectra spectra;
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(request.session_id());
  batch.set_method(v1::INTERPOLATION_METHOD_NEAREST);
  batch.set_quantity(request.quantity());
  *batch.mutable_options() = request.options();
  for (const v1::InterpolationVertex& v : result.vertices()) {
    *batch.add_directions() = VertexQuery(v);
  }
  auto context = ctx.client.UnaryContext();
  auto reader = ctx.client.interpolation().InterpolateBatch(context.get(), batch);
  v1::InterpolateBatchChunk chunk;
  while (reader->Read(&chunk)) {
    for (const v1::InterpolationResult& r : chunk.results()) spectra.results.push_back(r);
  }
  const grpc::Status status = reader->Finish();
  if (!status.ok()) {
    spectra.note =
        "(vertex spectra unavailable: " + std::string(GrpcCodeName(status.error_code())) + ": " +
        status.error_message() + ")";
    spectra.results.clear();
  }
  return spectra;
}

// The blended readings: ids, positions, weights and their sum.
void PrintVertices(std::ostream& out, const v1::InterpolationResult& result,
                   const std::string& note) {
  out << "\nvertices (blended readings):\n";
  const bool four = result.vertices(0).coords_size() == 4;
  out << "  #   " << Cell("reading", 9)
      << (four ? Cell("θi", 9) + Cell("φi", 9) + Cell("θo", 9) + Cell("φo", 9)
               : Cell("θi", 9) + Cell("θo", 9) + Cell("φ", 9))
      << "weight\n";
  double sum = 0;
  for (int i = 0; i < result.vertices_size(); ++i) {
    const v1::InterpolationVertex& v = result.vertices(i);
    sum += v.weight();
    out << "  " << Cell("v" + std::to_string(i + 1), 4) << Cell(std::to_string(v.reading_id()), 9)
        << CoordsText(v) << Num(v.weight(), 6) << "\n";
  }
  out << "  weights sum to " << Num(sum, 8) << "\n";
  if (!note.empty()) out << "  " << note << "\n";
}

// "±" and k times band b of `values`, or "-" when it has no such band.
std::string PlusMinus(const google::protobuf::RepeatedField<float>& values, int b, double k) {
  return b < values.size() ? "±" + Num(k * values.Get(b), 3) : "-";
}

// The uncertainty's header cells (none without one).
std::string UncertaintyHeader(const v1::InterpolationResult& result) {
  if (!result.has_uncertainty()) return "";
  return Cell("± meas.", 12) + Cell("± interp.", 12) + Cell("± total", 12);
}

// What the ± columns are, and what they leave out.
void PrintUncertaintyNote(std::ostream& out, const v1::InterpolationResult& result, double k) {
  if (!result.has_uncertainty()) return;
  out << "  ± columns: expanded uncertainties U = k·u, k = " << Num(k, 3)
      << " (meas.: the readings' budgets, shared terms correlated; interp.: the vertices' "
         "spread; total: both)\n";
  for (const std::string& s : result.uncertainty().not_estimated()) {
    out << "  not estimated: " << s << "\n";
  }
}

// The table of wavelength and value (every Nth band), with its ± columns and a column per
// vertex spectrum.
void PrintSpectra(std::ostream& out, const v1::InterpolationResult& result,
                  const std::vector<v1::InterpolationResult>& vertex_results, int every, double k) {
  const v1::WavelengthGrid& g = result.grid();
  const v1::InterpolationUncertainty& u = result.uncertainty();
  out << "\n" << Cell("λ (nm)", 9) << Cell("interpolated", 14) << UncertaintyHeader(result);
  for (std::size_t i = 0; i < vertex_results.size(); ++i) {
    out << Cell("v" + std::to_string(i + 1), 14);
  }
  out << "\n";
  for (int b = 0; b<result.spectrum_size(); b += every> 0 ? every : 1) {
    out << Cell(Num(g.start_nm() + b * g.step_nm()), 9) << Cell(Num(result.spectrum(b), 6), 14);
    if (result.has_uncertainty()) {
      out << Cell(PlusMinus(u.measurement(), b, k), 12)
          << Cell(PlusMinus(u.interpolation(), b, k), 12)
          << Cell(PlusMinus(u.combined(), b, k), 12);
    }
    for (const v1::InterpolationResult& r : vertex_results) {
      out << Cell(b < r.spectrum_size() ? Num(r.spectrum(b), 6) : "-", 14);
    }
    out << "\n";
  }
  for (std::size_t i = 0; i < vertex_results.size(); ++i) {
    const v1::InterpolationResult& r = vertex_results[i];
    const std::int64_t got = r.vertices_size() > 0 ? r.vertices(0).reading_id() : 0;
    if (got != result.vertices(static_cast<int>(i)).reading_id()) {
      out << "  note: v" << (i + 1) << "'s column is reading " << got
          << ", taken at the same direction as reading "
          << result.vertices(static_cast<int>(i)).reading_id() << "\n";
    }
  }
}

void PrintReadable(std::ostream& out, const InterpolateOptions& o,
                   const v1::InterpolateRequest& request, const v1::InterpolationResult& result,
                   const VertexSpectra& vertex_spectra) {
  out << "session " << o.session_id << ": " << QuantityName(result.quantity()) << " ("
      << QuantityUnit(result.quantity()) << ") at " << QueryText(result.query()) << ", "
      << MethodName(result.method())
      << (request.options().coordinates() == v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE
              ? " in half/difference coordinates"
              : "")
      << (request.options().trend() == v1::INTERPOLATION_TREND_BIVARIATE
              ? " over the bivariate trend"
              : "")
      << ": " << InterpolationStatusName(result.status()) << "\n";
  if (!result.detail().empty()) out << "  " << result.detail() << "\n";
  if (o.explain && result.vertices_size() > 0) PrintVertices(out, result, vertex_spectra.note);
  if (result.status() == v1::INTERPOLATION_STATUS_OK) {
    PrintSpectra(out, result, vertex_spectra.results, o.every, o.k);
    PrintUncertaintyNote(out, result, o.k);
  }
}

// What to try when the method found no spectrum: the symmetry flags not given that fill the
// point (asked of the daemon with the same request), else another method or direction.
std::string NoResultHint(CommandContext& ctx, const v1::InterpolateRequest& request) {
  const v1::InterpolationOptions& given = request.options();
  struct Try {
    bool mirror_phi, reciprocity;
    const char* flags;
  };
  for (const Try& t : {Try{true, false, "--mirror-phi"}, Try{false, true, "--reciprocity"},
                       Try{true, true, "--mirror-phi --reciprocity"}}) {
    if ((t.mirror_phi && given.mirror_phi()) || (t.reciprocity && given.reciprocity())) continue;
    v1::InterpolateRequest again = request;
    again.mutable_options()->set_mirror_phi(given.mirror_phi() || t.mirror_phi);
    again.mutable_options()->set_reciprocity(given.reciprocity() || t.reciprocity);
    v1::InterpolateResponse reply;
    const grpc::Status st =
        ctx.client.interpolation().Interpolate(ctx.client.UnaryContext().get(), again, &reply);
    if (st.ok() && reply.result().status() == v1::INTERPOLATION_STATUS_OK) {
      return std::string("; ") + t.flags +
             " fills it (the readings' symmetric copies close the gap), or try --method nearest";
    }
  }
  return "; try --method nearest, or a direction inside the measured range";
}

}  // namespace

int RunInterpolate(CommandContext& ctx, const InterpolateOptions& o) {
  v1::InterpolateRequest request;
  if (int rc = BuildRequest(ctx, o, &request); rc != kExitOk) return rc;
  v1::InterpolateResponse reply;
  const grpc::Status status =
      ctx.client.interpolation().Interpolate(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) {
    return ReportRpcError(ctx.err, status, "Interpolate", ctx.client.options().address);
  }
  const v1::InterpolationResult& result = reply.result();
  const bool ok = result.status() == v1::INTERPOLATION_STATUS_OK;
  VertexSpectra vertex_spectra;
  if (o.explain && ok && result.vertices_size() > 0) {
    vertex_spectra = FetchVertexSpectra(ctx, request, result);
  }
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
    for (const v1::InterpolationResult& r : vertex_spectra.results) PrintJsonLine(ctx.out, r);
  } else {
    PrintReadable(ctx.out, o, request, result, vertex_spectra);
  }
  if (!ok) {
    ctx.err << "brdfctl: no spectrum at " << QueryText(result.query()) << ": "
            << InterpolationStatusName(result.status())
            << (result.detail().empty() ? "" : " (" + result.detail() + ")")
            << NoResultHint(ctx, request) << "\n";
    return kExitNoResult;
  }
  return kExitOk;
}

namespace {

// The options and the three φ flags, whose presence CLI11 reports after parsing.
struct InterpolateArgs {
  InterpolateOptions options;
  double phi = 0, phi_i = 0, phi_o = 0;
  CLI::Option* phi_flag = nullptr;
  CLI::Option* phi_i_flag = nullptr;
  CLI::Option* phi_o_flag = nullptr;
};

void AddDirectionFlags(CLI::App& cmd, InterpolateArgs& a) {
  cmd.add_option("--theta-i", a.options.theta_i, "incidence polar angle θi, degrees")->required();
  cmd.add_option("--theta-o", a.options.theta_o, "outgoing polar angle θo, degrees")->required();
  a.phi_flag = cmd.add_option(
      "--phi", a.phi, "relative azimuth φ = |φo − φi|, degrees, 180 = specular side (isotropic)");
  a.phi_i_flag = cmd.add_option("--phi-i", a.phi_i, "incidence azimuth φi, degrees (anisotropic)");
  a.phi_o_flag = cmd.add_option("--phi-o", a.phi_o, "outgoing azimuth φo, degrees (anisotropic)");
  a.phi_flag->excludes(a.phi_i_flag)->excludes(a.phi_o_flag);
  a.phi_i_flag->needs(a.phi_o_flag);
  a.phi_o_flag->needs(a.phi_i_flag);
}

void AddMethodFlags(CLI::App& cmd, InterpolateOptions& o) {
  cmd.add_option("--method", o.method, "octant (the paper's), delaunay, nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}))
      ->capture_default_str();
  cmd.add_option("--quantity", o.quantity,
                 "radiance (W·m⁻²·sr⁻¹·nm⁻¹), reflectance (R = I/I0) or brdf (sr⁻¹)")
      ->check(CLI::IsMember({"radiance", "reflectance", "brdf"}))
      ->capture_default_str();
  cmd.add_flag("--explain", o.explain,
               "also the blended readings, their weights and their own spectra");
  cmd.add_option("--every", o.every, "print every Nth wavelength")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd.add_option("--k", o.k, "coverage factor of the ± columns: U = k · u (default 2, about 95 %)")
      ->check(CLI::PositiveNumber);
  cmd.add_flag("!--no-uncertainty", o.uncertainty, "leave the ± columns out");
  cmd.add_flag("--mirror-phi", o.mirror_phi, "also use readings mirrored to −φ");
  cmd.add_flag("--reciprocity", o.reciprocity, "also use readings with θi and θo swapped");
  cmd.add_option("--scale", o.axis_scale, "per-axis distance multipliers a,b,c[,d]")
      ->delimiter(',');
  cmd.add_option("--coordinates", o.coordinates,
                 "incidence (θi, θo, φ) or half-diff (Rusinkiewicz's half/difference angles; "
                 "isotropic sessions)")
      ->check(CLI::IsMember({"incidence", "half-diff"}))
      ->capture_default_str();
  cmd.add_option("--trend", o.trend,
                 "none, or bivariate: blend the readings' residuals from a fitted smooth "
                 "f(θh, θd) and add it back (isotropic sessions)")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();
}

Runner AddInterpolateOptions(CLI::App& cmd) {
  auto args = std::make_shared<InterpolateArgs>();
  AddSessionId(cmd, args->options.session_id);
  AddDirectionFlags(cmd, *args);
  AddMethodFlags(cmd, args->options);
  return OnDaemon([args](CommandContext& ctx) {
    InterpolateOptions options = args->options;
    if (args->phi_flag->count() > 0) options.phi = args->phi;
    if (args->phi_i_flag->count() > 0) options.phi_i = args->phi_i;
    if (args->phi_o_flag->count() > 0) options.phi_o = args->phi_o;
    return RunInterpolate(ctx, options);
  });
}

}  // namespace

void RegisterInterpolateCommand(CommandRegistry& registry) {
  registry.Add({"interpolate", "the spectrum at a direction between the samples of a session", "",
                AddInterpolateOptions});
}

}  // namespace brdf::ctl
