#include "tools/brdfctl/interpolate_command.h"

#include <cmath>
#include <cstdio>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/json_output.h"
#include "tools/brdfctl/rpc_error.h"
#include "tools/brdfctl/text_format.h"

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

}  // namespace

int RunInterpolate(CommandContext& ctx, const InterpolateOptions& o) {
  v1::InterpolateRequest request;
  request.set_session_id(o.session_id);
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
  request.set_method(method);
  request.set_quantity(quantity);
  if (o.phi) {
    v1::IsoDirection* d = request.mutable_direction()->mutable_iso();
    d->set_theta_i(o.theta_i);
    d->set_theta_o(o.theta_o);
    d->set_phi(*o.phi);
  } else if (o.phi_i && o.phi_o) {
    v1::Directions* d = request.mutable_direction()->mutable_four();
    d->set_theta_i(o.theta_i);
    d->set_phi_i(*o.phi_i);
    d->set_theta_o(o.theta_o);
    d->set_phi_o(*o.phi_o);
  } else {
    ctx.err << "brdfctl: give --phi (isotropic: θi, θo, φ) or both --phi-i and --phi-o\n";
    return kExitInvalid;
  }
  v1::InterpolationOptions* options = request.mutable_options();
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

  v1::InterpolateResponse reply;
  grpc::Status status =
      ctx.client.interpolation().Interpolate(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) {
    return ReportRpcError(ctx.err, status, "Interpolate", ctx.client.options().address);
  }
  const v1::InterpolationResult& result = reply.result();
  const bool ok = result.status() == v1::INTERPOLATION_STATUS_OK;

  // The vertices' own spectra, for --explain.
  std::vector<v1::InterpolationResult> vertex_results;
  std::string vertex_note;
  if (o.explain && ok && result.vertices_size() > 0) {
    v1::InterpolateBatchRequest batch;
    batch.set_session_id(o.session_id);
    batch.set_method(v1::INTERPOLATION_METHOD_NEAREST);
    batch.set_quantity(quantity);
    *batch.mutable_options() = request.options();
    for (const v1::InterpolationVertex& v : result.vertices()) {
      *batch.add_directions() = VertexQuery(v);
    }
    auto context = ctx.client.UnaryContext();
    auto reader = ctx.client.interpolation().InterpolateBatch(context.get(), batch);
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
      for (const v1::InterpolationResult& r : chunk.results()) vertex_results.push_back(r);
    }
    status = reader->Finish();
    if (!status.ok()) {
      vertex_note =
          "(vertex spectra unavailable: " + std::string(GrpcCodeName(status.error_code())) + ": " +
          status.error_message() + ")";
      vertex_results.clear();
    }
  }

  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
    for (const v1::InterpolationResult& r : vertex_results) PrintJsonLine(ctx.out, r);
  } else {
    std::ostream& out = ctx.out;
    out << "session " << o.session_id << ": " << QuantityName(result.quantity()) << " ("
        << QuantityUnit(result.quantity()) << ") at " << QueryText(result.query()) << ", "
        << MethodName(result.method())
        << (coordinates == v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE
                ? " in half/difference coordinates"
                : "")
        << (trend == v1::INTERPOLATION_TREND_BIVARIATE ? " over the bivariate trend" : "") << ": "
        << InterpolationStatusName(result.status()) << "\n";
    if (!result.detail().empty()) out << "  " << result.detail() << "\n";
    if (o.explain && result.vertices_size() > 0) {
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
        out << "  " << Cell("v" + std::to_string(i + 1), 4)
            << Cell(std::to_string(v.reading_id()), 9) << CoordsText(v) << Num(v.weight(), 6)
            << "\n";
      }
      out << "  weights sum to " << Num(sum, 8) << "\n";
      if (!vertex_note.empty()) out << "  " << vertex_note << "\n";
    }
    if (ok) {
      const v1::WavelengthGrid& g = result.grid();
      out << "\n" << Cell("λ (nm)", 9) << Cell("interpolated", 14);
      for (std::size_t i = 0; i < vertex_results.size(); ++i) {
        out << Cell("v" + std::to_string(i + 1), 14);
      }
      out << "\n";
      const int every = o.every > 0 ? o.every : 1;
      for (int b = 0; b < result.spectrum_size(); b += every) {
        out << Cell(Num(g.start_nm() + b * g.step_nm()), 9) << Cell(Num(result.spectrum(b), 6), 14);
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
  }
  if (!ok) {
    ctx.err << "brdfctl: no spectrum at " << QueryText(result.query()) << ": "
            << InterpolationStatusName(result.status())
            << (result.detail().empty() ? "" : " (" + result.detail() + ")")
            << "; try --method nearest, or a direction inside the measured range\n";
    return kExitNoResult;
  }
  return kExitOk;
}

}  // namespace brdf::ctl
