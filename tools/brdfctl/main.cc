// brdfctl: the command line for brdfd. Every API call is a subcommand (README.md):
//   brdfctl validate|submit PLAN.json, start|pause|resume|abort|get|watch|readings ID,
//   answer ID STEP, list, rig, interpolate ID --theta-i A --theta-o B --phi C,
//   export ID csv|grid|merl|rgl [-o FILE], appearance ID [--illuminant D65|A] [-o FILE.ppm]
// plus `sim-mount` for the simulated rig only. Address and token from --address/--token or
// BRDF_ADDRESS/BRDF_TOKEN. Exit status: exit_codes.h.
#include <sys/ioctl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "tools/brdfctl/appearance_command.h"
#include "tools/brdfctl/client.h"
#include "tools/brdfctl/control_commands.h"
#include "tools/brdfctl/exit_codes.h"
#include "tools/brdfctl/export_command.h"
#include "tools/brdfctl/interpolate_command.h"
#include "tools/brdfctl/readings_command.h"
#include "tools/brdfctl/rpc_error.h"
#include "tools/brdfctl/sim_mount.h"
#include "tools/brdfctl/watch_command.h"

namespace {

using namespace brdf::ctl;

constexpr const char* kFooter = R"(
Environment: BRDF_ADDRESS (default 127.0.0.1:50051), BRDF_TOKEN (the bearer token; --token-file
reads it from a file instead). Flags override the environment.
Output is readable by default; --json prints each reply as protobuf JSON, one object per line.
Exit status: 0 done, 1 failure (daemon unreachable, other errors), 2 invalid argument (bad plan,
bad flag), 3 authentication (no, wrong or too weak a token), 4 no result (watch: the session
ended aborted or failed; interpolate: no spectrum at that direction).)";

int TerminalWidth() {
  winsize ws{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
  if (const char* columns = std::getenv("COLUMNS")) {
    const int n = std::atoi(columns);
    if (n > 0) return n;
  }
  return 80;
}

// The first line of a token file, without surrounding whitespace.
bool ReadTokenFile(const std::string& path, std::string* token) {
  std::ifstream in(path);
  if (!in) return false;
  std::getline(in, *token);
  const auto first = token->find_first_not_of(" \t\r\n");
  const auto last = token->find_last_not_of(" \t\r\n");
  *token = first == std::string::npos ? "" : token->substr(first, last - first + 1);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"brdfctl: control brdfd (spectral BRDF measurement daemon) and query its data"};
  app.footer(kFooter);
  app.require_subcommand(1);
  app.fallthrough();  // global flags may come after the subcommand too

  ClientOptions client_options;
  std::string token_file;
  double timeout_s = 10;
  bool json = false;
  app.add_option("--address", client_options.address, "brdfd's host:port (or unix:/path)")
      ->envname("BRDF_ADDRESS")
      ->capture_default_str();
  app.add_option("--token", client_options.token, "bearer token (operator or analyst)")
      ->envname("BRDF_TOKEN");
  app.add_option("--token-file", token_file, "read the bearer token from this file's first line");
  app.add_flag("--tls", client_options.tls, "connect with TLS");
  app.add_option("--ca", client_options.ca_file, "TLS: PEM roots to trust (default: the system's)");
  app.add_option("--cert", client_options.cert_file, "TLS: client certificate (mutual TLS)");
  app.add_option("--key", client_options.key_file, "TLS: client private key (mutual TLS)");
  app.add_option("--timeout", timeout_s, "seconds to wait for each call (streams excepted)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--json", json, "print replies as protobuf JSON, one object per line");

  // Plans.
  std::string plan_path;
  CLI::App* validate = app.add_subcommand(
      "validate",
      "check a plan file against the rig: every problem with its field path, or the "
      "step count and duration");
  validate->add_option("plan", plan_path, "plan JSON file (- for standard input)")->required();
  double time_scale = 1.0;
  validate
      ->add_option("--time-scale", time_scale,
                   "estimate for a simulated rig this many times faster (brdf-sim "
                   "--time-scale; the quick start's is 8)")
      ->check(CLI::Range(0.001, 1e6));

  bool start_now = false;
  bool quiet = false;
  CLI::App* submit = app.add_subcommand("submit", "submit a plan file as a new session");
  submit->add_option("plan", plan_path, "plan JSON file (- for standard input)")->required();
  submit->add_flag("--start", start_now, "start it at once (else it stays queued)");
  submit->add_flag("-q,--quiet", quiet, "print only the new session's id");

  // Operator verbs.
  std::string session_id;
  auto add_id = [&session_id](CLI::App* cmd) {
    cmd->add_option("id", session_id, "session id (brdfctl list)")->required();
  };
  CLI::App* start = app.add_subcommand("start", "start a queued session");
  add_id(start);
  bool immediate = false;
  CLI::App* pause = app.add_subcommand(
      "pause",
      "pause a session after the current step (--immediate: cancel the step now; resume "
      "redoes it)");
  add_id(pause);
  pause->add_flag("--immediate", immediate, "cancel the step in progress now");
  CLI::App* resume = app.add_subcommand("resume", "resume a paused session");
  add_id(resume);
  std::string reason;
  CLI::App* abort_cmd =
      app.add_subcommand("abort", "stop a session for good (its readings are kept)");
  add_id(abort_cmd);
  abort_cmd->add_option("--reason", reason, "why (stored with the session)");
  int step_index = -1;
  std::string note;
  CLI::App* answer = app.add_subcommand(
      "answer", "confirm the operator prompt at STEP once its manual action is done");
  add_id(answer);
  answer->add_option("step", step_index, "the prompt's step index (brdfctl get ID shows it)")
      ->required();
  answer->add_option("--note", note, "remark stored with the session's log");

  // Views.
  CLI::App* get = app.add_subcommand("get", "one session: state, progress, prompt, fault, plan");
  add_id(get);
  CLI::App* events = app.add_subcommand(
      "events", "a session's history of states, oldest first: time, state, reason");
  add_id(events);
  std::vector<std::string> states;
  unsigned limit = 0;
  CLI::App* list = app.add_subcommand("list", "sessions, newest first");
  list->add_option("--state", states,
                   "only these states: queued, running, pausing, paused, awaiting_operator, "
                   "completed, aborted, failed (repeat or comma-separate)")
      ->delimiter(',');
  list->add_option("--limit", limit, "at most this many (0: all)");
  ListFilters list_filters;
  list->add_option("--rig", list_filters.rig, "only sessions recorded by this rig ([rig] name)");
  list->add_option("--sample", list_filters.sample,
                   "only sessions of this sample: its id, or its name (ignoring case)");
  list->add_option("--material", list_filters.material,
                   "only sessions of samples of this material (ignoring case)");
  list->add_option("--tag", list_filters.tag, "only sessions of samples carrying this tag");
  CLI::App* rig = app.add_subcommand("rig", "the rig: devices, axes, live pose, meter serial");

  WatchOptions watch_options;
  bool no_progress = false;
  CLI::App* watch = app.add_subcommand(
      "watch", "follow a session live until it ends, confirming operator prompts");
  add_id(watch);
  watch->add_flag("--auto-confirm", watch_options.auto_confirm,
                  "confirm every prompt without asking");
  watch->add_option("--on-prompt", watch_options.on_prompt,
                    "shell command run before confirming a prompt; sees BRDF_PROMPT_KIND, "
                    "BRDF_PROMPT_STEP, BRDF_PROMPT_TEXT, BRDF_SESSION_ID, BRDF_PROMPT_DELTA …");
  bool force_ask = false;
  watch->add_flag("--ask", force_ask,
                  "ask y/N for each prompt on standard input even when it is not a terminal");
  watch->add_flag("--no-progress", no_progress, "plain lines even on a terminal");
  watch->add_flag("--exit-on-pause", watch_options.exit_on_pause,
                  "stop watching (exit 4) when the session pauses, e.g. after a device fault");

  ReadingsOptions readings_options;
  CLI::App* readings = app.add_subcommand("readings", "a session's readings, in the order taken");
  add_id(readings);
  readings->add_flag("--follow", readings_options.follow,
                     "keep going: print new readings as they are taken, until the session ends");
  readings
      ->add_option("--kind", readings_options.kinds,
                   "only sample, reference or dark (repeat or comma-separate)")
      ->delimiter(',');
  readings->add_option("--after-id", readings_options.after_id, "only readings with a larger id");
  readings->add_flag("--spectra", readings_options.spectra, "also print each spectrum");

  InterpolateOptions interp;
  double phi = 0, phi_i = 0, phi_o = 0;
  CLI::App* interpolate = app.add_subcommand(
      "interpolate", "the spectrum at a direction between the samples of a session");
  add_id(interpolate);
  interpolate->add_option("--theta-i", interp.theta_i, "incidence polar angle θi, degrees")
      ->required();
  interpolate->add_option("--theta-o", interp.theta_o, "outgoing polar angle θo, degrees")
      ->required();
  CLI::Option* phi_opt = interpolate->add_option(
      "--phi", phi, "relative azimuth φ = |φo − φi|, degrees, 180 = specular side (isotropic)");
  CLI::Option* phi_i_opt =
      interpolate->add_option("--phi-i", phi_i, "incidence azimuth φi, degrees (anisotropic)");
  CLI::Option* phi_o_opt =
      interpolate->add_option("--phi-o", phi_o, "outgoing azimuth φo, degrees (anisotropic)");
  phi_opt->excludes(phi_i_opt)->excludes(phi_o_opt);
  phi_i_opt->needs(phi_o_opt);
  phi_o_opt->needs(phi_i_opt);
  interpolate->add_option("--method", interp.method, "octant (the paper's), delaunay, nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}))
      ->capture_default_str();
  interpolate
      ->add_option("--quantity", interp.quantity,
                   "radiance (W·m⁻²·sr⁻¹·nm⁻¹), reflectance (R = I/I0) or brdf (sr⁻¹)")
      ->check(CLI::IsMember({"radiance", "reflectance", "brdf"}))
      ->capture_default_str();
  interpolate->add_flag("--explain", interp.explain,
                        "also the blended readings, their weights and their own spectra");
  interpolate->add_option("--every", interp.every, "print every Nth wavelength")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  interpolate->add_flag("--mirror-phi", interp.mirror_phi, "also use readings mirrored to −φ");
  interpolate->add_flag("--reciprocity", interp.reciprocity,
                        "also use readings with θi and θo swapped");
  interpolate->add_option("--scale", interp.axis_scale, "per-axis distance multipliers a,b,c[,d]")
      ->delimiter(',');
  interpolate
      ->add_option("--coordinates", interp.coordinates,
                   "incidence (θi, θo, φ) or half-diff (Rusinkiewicz's half/difference angles; "
                   "isotropic sessions)")
      ->check(CLI::IsMember({"incidence", "half-diff"}))
      ->capture_default_str();
  interpolate
      ->add_option("--trend", interp.trend,
                   "none, or bivariate: blend the readings' residuals from a fitted smooth "
                   "f(θh, θd) and add it back (isotropic sessions)")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();

  AppearanceOptions appearance_options;
  CLI::App* appearance = app.add_subcommand(
      "appearance",
      "the sample's colour (45°:0°) and a lit sphere in sRGB under D65 and illuminant A");
  add_id(appearance);
  appearance->add_option("--illuminant", appearance_options.illuminant, "D65 or A (default both)")
      ->check(CLI::IsMember({"D65", "A"}));
  appearance
      ->add_option("--method", appearance_options.method, "octant (the paper's), delaunay, nearest")
      ->check(CLI::IsMember({"octant", "delaunay", "nearest"}))
      ->capture_default_str();
  appearance->add_option("--size", appearance_options.size,
                         "the sphere's pixels per side, at most 512 (default 128)");
  appearance->add_option("-o,--output", appearance_options.output,
                         "write the sphere as a PPM (both illuminants: NAME-D65.ppm, NAME-A.ppm)");

  ExportOptions export_options;
  bool export_no_progress = false;
  CLI::App* export_cmd = app.add_subcommand(
      "export",
      "a session as a file: readings CSV, a regular grid (.npy or CSV), a MERL .binary, an RGL "
      ".bsdf");
  add_id(export_cmd);
  export_cmd->add_option("what", export_options.what, "csv, grid, merl or rgl")
      ->required()
      ->check(CLI::IsMember({"csv", "grid", "merl", "rgl"}));
  export_cmd->add_option("-o,--output", export_options.output,
                         "the file (default: the daemon's name for it, e.g. "
                         "session-1-grid-brdf.npy); - for standard output (csv)");
  export_cmd
      ->add_option("--quantity", export_options.quantity,
                   "csv, grid: radiance, reflectance or brdf")
      ->capture_default_str();
  export_cmd->add_option("--format", export_options.format,
                         "grid: npy or csv (default: from the file's extension, else npy)");
  export_cmd
      ->add_option("--steps", export_options.steps,
                   "grid: dθi,dθo,dφ in degrees, or one for all (default 1: 90 × 90 × 180 cells)")
      ->delimiter(',');
  export_cmd->add_flag("--nodes", export_options.nodes,
                       "grid: nodes 0, step, …, 90 (180) instead of the cells' centres");
  export_cmd
      ->add_option("--method", export_options.method, "octant (the paper's), delaunay, nearest")
      ->capture_default_str();
  export_cmd
      ->add_option("--scale", export_options.axis_scale, "per-axis distance multipliers a,b,c")
      ->delimiter(',');
  export_cmd->add_flag("--mirror-phi", export_options.mirror_phi,
                       "also use readings mirrored to −φ");
  export_cmd
      ->add_option("--coordinates", export_options.coordinates,
                   "grid, merl, rgl: interpolate in incidence (θi, θo, φ) or half-diff "
                   "(Rusinkiewicz's half/difference angles) coordinates")
      ->check(CLI::IsMember({"incidence", "half-diff"}))
      ->capture_default_str();
  export_cmd
      ->add_option("--trend", export_options.trend,
                   "grid, merl, rgl: none, or bivariate (blend the readings' residuals from a "
                   "fitted smooth f(θh, θd) and add it back)")
      ->check(CLI::IsMember({"none", "bivariate"}))
      ->capture_default_str();
  export_cmd->add_flag("--reciprocity", export_options.reciprocity,
                       "grid: also use readings with θi and θo swapped (merl, rgl: always, see "
                       "below)");
  export_cmd->add_flag("--no-reciprocity", export_options.no_reciprocity,
                       "merl, rgl: do not add the θi↔θo swapped readings");
  export_cmd
      ->add_option("--fill", export_options.fill,
                   "grid, merl, rgl: cells the method cannot fill: chain (Delaunay, then the "
                   "fitted Cook-Torrance model) or none (NaN / −1)")
      ->check(CLI::IsMember({"chain", "none"}))
      ->capture_default_str();
  export_cmd->add_flag("--rgb", export_options.rgb,
                       "rgl: linear sRGB under D65 (field rgb) instead of spectra");
  export_cmd->add_option("--theta-i", export_options.theta_i_count, "rgl: θi slices (default 24)");
  export_cmd->add_option("--resolution", export_options.resolution,
                         "rgl: nodes per side of the warped square (default 48)");
  export_cmd->add_flag("--exclude-flagged", export_options.exclude_flagged,
                       "leave out readings the quality policy flagged");
  export_cmd->add_flag("--no-progress", export_no_progress, "no progress line");

  std::string sim_target;
  std::string sim_modbus;
  int sim_unit = 100;
  CLI::App* sim_mount = app.add_subcommand(
      "sim-mount",
      "SIMULATOR ONLY: mount sample, white or dark on brdf-sim (from-prompt: what "
      "$BRDF_PROMPT_KIND asks)");
  sim_mount->group("Simulator only (brdf-sim)");
  sim_mount->add_option("target", sim_target, "sample, white, dark or from-prompt")->required();
  sim_mount->add_option("--modbus", sim_modbus, "brdf-sim's Modbus TCP host:port")
      ->envname("BRDF_SIM_MODBUS")
      ->required();
  sim_mount->add_option("--unit", sim_unit, "brdf-sim's control unit id")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and friends are "errors" with exit code 0; usage errors exit 2 (a bad argument).
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitInvalid;
  }

  if (sim_mount->parsed()) {
    return RunSimMount(std::cout, std::cerr, sim_target, sim_modbus, sim_unit);
  }

  if (!token_file.empty() && !ReadTokenFile(token_file, &client_options.token)) {
    std::cerr << "brdfctl: --token-file " << token_file << ": cannot read it\n";
    return kExitInvalid;
  }
  client_options.timeout = std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  brdf::Result<std::unique_ptr<Client>> client = Client::Create(client_options);
  if (!client.ok()) return ReportLocalError(std::cerr, client.status());
  CommandContext ctx{**client, json, std::cout, std::cerr};

  if (validate->parsed()) return RunValidate(ctx, plan_path, time_scale);
  if (submit->parsed()) return RunSubmit(ctx, plan_path, start_now, quiet);
  if (start->parsed()) return RunStart(ctx, session_id);
  if (pause->parsed()) return RunPause(ctx, session_id, immediate);
  if (resume->parsed()) return RunResume(ctx, session_id);
  if (abort_cmd->parsed()) return RunAbort(ctx, session_id, reason);
  if (answer->parsed()) return RunAnswer(ctx, session_id, step_index, note);
  if (get->parsed()) return RunGet(ctx, session_id);
  if (events->parsed()) return RunEvents(ctx, session_id);
  if (list->parsed()) return RunList(ctx, states, limit, list_filters);
  if (rig->parsed()) return RunRig(ctx);
  if (watch->parsed()) {
    watch_options.session_id = session_id;
    const bool tty_out = isatty(STDOUT_FILENO) != 0;
    watch_options.progress_bar = tty_out && !json && !no_progress;
    watch_options.ask =
        (force_ask || (tty_out && isatty(STDIN_FILENO) != 0)) && !watch_options.auto_confirm;
    watch_options.width = TerminalWidth();
    return RunWatch(ctx, watch_options);
  }
  if (readings->parsed()) {
    readings_options.session_id = session_id;
    return RunReadings(ctx, readings_options);
  }
  if (appearance->parsed()) {
    appearance_options.session_id = session_id;
    return RunAppearance(ctx, appearance_options);
  }
  if (export_cmd->parsed()) {
    export_options.session_id = session_id;
    export_options.progress = !export_no_progress;
    export_options.progress_tty = isatty(STDERR_FILENO) != 0;
    return RunExport(ctx, export_options);
  }
  if (interpolate->parsed()) {
    interp.session_id = session_id;
    if (phi_opt->count() > 0) interp.phi = phi;
    if (phi_i_opt->count() > 0) interp.phi_i = phi_i;
    if (phi_o_opt->count() > 0) interp.phi_o = phi_o;
    return RunInterpolate(ctx, interp);
  }
  std::cerr << app.help();
  return kExitInvalid;
}
