#include "tools/brdfctl/commands/appearance.h"

#include <CLI/CLI.hpp>
#include <fstream>
#include <memory>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {
namespace {

// "sphere.ppm" → "sphere-D65.ppm" when there is more than one image.
std::string FileFor(const std::string& output, const std::string& name, bool several) {
  if (!several) return output;
  const std::size_t dot = output.rfind('.');
  const std::size_t slash = output.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
    return output + "-" + name;
  }
  return output.substr(0, dot) + "-" + name + output.substr(dot);
}

// RGBA over white, as a binary PPM.
bool WritePpm(const std::string& path, const v1::AppearanceImage& image) {
  std::ofstream out(path, std::ios::binary);
  if (!out) return false;
  const std::uint32_t n = image.sphere_size();
  out << "P6\n" << n << " " << n << "\n255\n";
  const std::string& rgba = image.sphere_rgba();
  for (std::size_t i = 0; i + 3 < rgba.size(); i += 4) {
    const auto alpha = static_cast<unsigned char>(rgba[i + 3]);
    for (int k = 0; k < 3; ++k) {
      out.put(alpha == 0 ? static_cast<char>(255) : rgba[i + static_cast<std::size_t>(k)]);
    }
  }
  return static_cast<bool>(out);
}

}  // namespace

int RunAppearance(CommandContext& ctx, const AppearanceOptions& o) {
  v1::AppearanceRequest request;
  request.set_session_id(o.session_id);
  if (o.method == "octant") {
    request.set_method(v1::INTERPOLATION_METHOD_OCTANT);
  } else if (o.method == "delaunay") {
    request.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  } else if (o.method == "nearest") {
    request.set_method(v1::INTERPOLATION_METHOD_NEAREST);
  } else {
    ctx.err << "brdfctl: --method " << o.method << ": use octant, delaunay or nearest\n";
    return kExitInvalid;
  }
  if (o.illuminant == "D65") {
    request.add_illuminants(v1::ILLUMINANT_D65);
  } else if (o.illuminant == "A") {
    request.add_illuminants(v1::ILLUMINANT_A);
  } else if (!o.illuminant.empty()) {
    ctx.err << "brdfctl: --illuminant " << o.illuminant << ": use D65 or A\n";
    return kExitInvalid;
  }
  request.set_sphere_size(o.size);

  v1::AppearanceResponse reply;
  const grpc::Status status =
      ctx.client.interpolation().RenderAppearance(ctx.client.UnaryContext().get(), request, &reply);
  if (!status.ok()) {
    return ReportRpcError(ctx.err, status, "RenderAppearance", ctx.client.options().address);
  }
  if (ctx.json) {
    PrintJsonLine(ctx.out, reply);
  } else {
    ctx.out << "session " << o.session_id
            << ": colour at 45°:0° (reflectance factor π·f_r), sRGB (IEC 61966-2-1)\n";
    for (const v1::AppearanceImage& image : reply.images()) {
      const v1::AppearanceColour& c = image.colour();
      ctx.out << "  " << (image.name() == "A" ? "A  " : "D65") << "  " << c.srgb_hex() << "  X "
              << Num(c.x_tristimulus(), 4) << "  Y " << Num(c.y_tristimulus(), 4) << "  Z "
              << Num(c.z_tristimulus(), 4) << "  x " << Num(c.x(), 4) << "  y " << Num(c.y(), 4)
              << "\n";
      ctx.out << "       sphere " << image.sphere_size() << "×" << image.sphere_size() << ": "
              << image.disc_pixels() - image.unlit_pixels() << " lit pixels ("
              << image.interpolated_pixels() << " interpolated, " << image.fallback_pixels()
              << " Delaunay, " << image.model_pixels() << " model)\n";
    }
    if (!reply.detail().empty()) ctx.out << "  " << reply.detail() << "\n";
  }
  if (!o.output.empty()) {
    const bool several = reply.images_size() > 1;
    for (const v1::AppearanceImage& image : reply.images()) {
      const std::string path = FileFor(o.output, image.name(), several);
      if (!WritePpm(path, image)) {
        ctx.err << "brdfctl: cannot write " << path << "\n";
        return kExitFailure;
      }
      ctx.err << "wrote " << path << "\n";
    }
  }
  return kExitOk;
}

namespace {

Runner AddAppearanceOptions(CLI::App& cmd) {
  auto options = std::make_shared<AppearanceOptions>();
  AddSessionId(cmd, options->session_id);
  cmd.add_option("--illuminant", options->illuminant, "D65 or A (default both)")
      ->check(CLI::IsMember({"D65", "A"}));
  cmd.add_option("--method", options->method, "octant (the paper's), delaunay, nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}))
      ->capture_default_str();
  cmd.add_option("--size", options->size,
                 "the sphere's pixels per side, at most 512 (default 128)");
  cmd.add_option("-o,--output", options->output,
                 "write the sphere as a PPM (both illuminants: NAME-D65.ppm, NAME-A.ppm)");
  return OnDaemon([options](CommandContext& ctx) { return RunAppearance(ctx, *options); });
}

}  // namespace

void RegisterAppearanceCommand(CommandRegistry& registry) {
  registry.Add({"appearance",
                "the sample's colour (45°:0°) and a lit sphere in sRGB under D65 and illuminant A",
                "", AddAppearanceOptions});
}

}  // namespace brdf::ctl
