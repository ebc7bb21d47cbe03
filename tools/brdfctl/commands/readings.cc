#include "tools/brdfctl/commands/readings.h"

#include <CLI/CLI.hpp>
#include <cctype>
#include <memory>

#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/output/json.h"
#include "tools/brdfctl/output/text_format.h"
#include "tools/brdfctl/output/uncertainty_text.h"
#include "tools/brdfctl/rpc_error.h"

namespace brdf::ctl {
namespace {

bool ParseKind(const std::string& name, v1::ReadingKind* kind) {
  std::string upper = "READING_KIND_";
  for (char c : name) upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return v1::ReadingKind_Parse(upper, kind) && *kind != v1::READING_KIND_UNSPECIFIED;
}

void PrintReading(std::ostream& out, const v1::Reading& r, bool spectra, double k) {
  out << r.id() << "  step " << r.step_index() << "  " << ReadingKindName(r.kind()) << "  "
      << PoseText(r.pose());
  if (r.kind() == v1::READING_KIND_SAMPLE) out << "  " << IsoText(r.iso());
  out << "  q " << r.quality_code() << "  ";
  if (r.integration_ms() == 0) {
    out << "adaptive";  // the PR-650 does not report the integration time it chose
  } else {
    out << r.integration_ms() << " ms";
  }
  if (r.averages() > 1) out << " ×" << r.averages();
  if (!r.integration_note().empty())
    out << " (changed by the meter: " << r.integration_note() << ")";
  if (r.flagged()) out << "  FLAGGED (" << r.flag_reason() << ")";
  if (!r.label().empty()) out << "  \"" << r.label() << "\"";
  const std::string uncertainty = UncertaintySummary(r, k);
  if (!uncertainty.empty()) out << "  " << uncertainty;
  out << "\n";
  if (!spectra) return;
  const v1::WavelengthGrid& g = r.grid();
  for (int i = 0; i < r.radiance_size(); ++i) {
    out << "    " << Num(g.start_nm() + i * g.step_nm()) << " nm  " << Num(r.radiance(i), 8);
    if (r.has_uncertainty()) out << "  " << UncertaintyBand(r.uncertainty(), i, k);
    out << "\n";
  }
}

}  // namespace

int RunReadings(CommandContext& ctx, const ReadingsOptions& options) {
  v1::StreamReadingsRequest request;
  request.set_session_id(options.session_id);
  request.set_follow(options.follow);
  request.set_after_id(options.after_id);
  for (const std::string& name : options.kinds) {
    v1::ReadingKind kind{};
    if (!ParseKind(name, &kind)) {
      ctx.err << "brdfctl: --kind " << name << " is not a reading kind; use sample, reference "
              << "or dark\n";
      return kExitInvalid;
    }
    request.add_kinds(kind);
  }
  auto context = ctx.client.StreamContext();
  if (!options.follow) {
    context->set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(10));
  }
  auto reader = ctx.client.data().StreamReadings(context.get(), request);
  v1::Reading reading;
  std::size_t count = 0;
  if (!ctx.json) {
    ctx.out << "id  step  kind  pose (stage readings)  direction  quality  integration  label  "
            << "± (k=" << Num(options.k, 3) << ")\n";
  }
  while (reader->Read(&reading)) {
    ++count;
    if (ctx.json) {
      PrintJsonLine(ctx.out, reading);
    } else {
      PrintReading(ctx.out, reading, options.spectra, options.k);
      if (options.follow) ctx.out.flush();
    }
  }
  const grpc::Status status = reader->Finish();
  if (!status.ok()) {
    return ReportRpcError(ctx.err, status, "StreamReadings", ctx.client.options().address);
  }
  if (!ctx.json) ctx.out << count << (count == 1 ? " reading" : " readings") << "\n";
  return kExitOk;
}

namespace {

Runner AddReadingsOptions(CLI::App& cmd) {
  auto options = std::make_shared<ReadingsOptions>();
  AddSessionId(cmd, options->session_id);
  cmd.add_flag("--follow", options->follow,
               "keep going: print new readings as they are taken, until the session ends");
  cmd.add_option("--kind", options->kinds,
                 "only sample, reference or dark (repeat or comma-separate)")
      ->delimiter(',');
  cmd.add_option("--after-id", options->after_id, "only readings with a larger id");
  cmd.add_flag("--spectra", options->spectra, "also print each spectrum");
  cmd.add_option("--k", options->k,
                 "coverage factor of the ± columns: U = k · u of each sample's BRDF (default 2, "
                 "about 95 %)")
      ->check(CLI::PositiveNumber);
  return OnDaemon([options](CommandContext& ctx) { return RunReadings(ctx, *options); });
}

}  // namespace

void RegisterReadingsCommand(CommandRegistry& registry) {
  registry.Add({"readings", "a session's readings, in the order taken", "", AddReadingsOptions});
}

}  // namespace brdf::ctl
