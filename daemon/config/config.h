// brdfd's configuration: one TOML file (e.g. /etc/brdfd/brdfd.toml). Every key is optional and
// has the default written next to it below; a file with a wrong type, a value out of range or a
// key brdfd does not know (a typo must not silently fall back to a default) is refused with
// kConfigurationError, naming every bad key with its line and the reason, one per line, then what
// to do (core/toml/table_reader.h, as every TOML file of brdfd):
//   config /etc/brdfd/brdfd.toml: line 31, column 1: unknown key stage.axes.alpa (known here:
//     alpha, beta, delta, gamma)
//   config /etc/brdfd/brdfd.toml: fix the file; brdfd.example.toml (deploy/, installed in
//     share/doc/brdfd/) shows every key with its default
//
//   [server]
//   listen = "127.0.0.1:50051"          # host:port (port 0: any free port) or "unix:/path"
//   interpolate_threads = 1             # Interpolate's loop threads (default: one per 2 cores)
//   interpolate_cpus = [1]              # pin them to these CPUs (default: not pinned)
//   memory_budget_mb = 2048             # heavy calls (exports, batches) refused beyond it
//   [server.tls]                        # optional; cert and key together; client_ca → mTLS
//   cert = "/etc/brdfd/server.crt"
//   key = "/etc/brdfd/server.key"
//   client_ca = "/etc/brdfd/clients-ca.crt"
//
//   [storage]
//   database = "/var/lib/brdfd/brdfd.db"
//
//   [meter]                             # the spectroradiometer (pr650.md, pr670-protocol.md,
//   model = "pr650"                     #   cs2000-protocol.md): pr650, pr655, pr670, cs2000,
//                                       #   cs2000a or cs3000
//   port = "/dev/ttyUSB0"
//   baud = 9600
//   hardware_flow_control = false
//   pacing_ms = 100                     # pause after an exchange before the next command
//   quiet_gap_ms = 50                   # silence that ends a reply
//   reply_timeout_ms = 2000             # short replies (B, D110, D120, D5)
//   measurement_timeout_ms = 30000      # S, F; margin of M0/M5 over averages × integration
//   wake_attempts = 5                   # remote-mode wake-up tries before asking for a power cycle
//   measure_with_spectrum = true        # M5 (one exchange per reading); false: M0 then D5
//   rts_settle_ms = 1000                # wait after RTS drop/raise before the first command
//   char_gap_ms = 50                    # PR-655/670: commands typed a character at a time
//   nd_filter = "auto"                  # CS-2000/3000: internal ND filter, "off", "on", "auto"
//   overhead_ms = 300                   # the meter's own time per reading (for estimates)
//   adaptive_reference_ms = 2000        # integration the meter is expected to choose when the
//   adaptive_dark_ms = 6000             #   plan says adaptive, by kind of reading (for
//   adaptive_sample_ms = 2000           #   estimates); 10 … 6000 ms, the meter's range
//   [meter.quality]                     # overrides of the quality policy, by code
//   "18" = "accept_and_flag"            # accept, accept_and_flag, retry, retry_then_flag,
//   "30" = { action = "retry", accept_flagged_when_exhausted = true }  # adapt_integration,
//                                                                      # sync_off_and_retry, fail
//   [stage]                             # the rotation stage over Modbus (stage-modbus.md)
//   transport = "tcp"                   # "tcp" or "rtu"
//   address = "127.0.0.1:502"           # tcp: host:port
//   device = "/dev/ttyUSB1"             # rtu: serial device (required for rtu)
//   baud = 115200                       # rtu
//   parity = "E"                        # rtu: "N", "E" or "O"
//   profile = "az"                      # register map: "az", "leadshine" or "moons"
//   profile_file = "/etc/brdfd/stage-profile.toml"  # or the lab's own map (a copy of one of
//                                       #   share/brdfd/stage-profiles/*.toml); not with profile
//   response_timeout_ms = 500
//   busy_window_ms = 3000               # exception 04/06 retried with back-off this long, then
//                                       #   the session pauses naming the exception
//   reconnect_max_ms = 1000             # longest wait between reconnection attempts
//   detector_arm_motorized = false      # true: δ is a Modbus axis ([stage.axes.delta] present)
//   [stage.axes.alpha]                  # also beta, gamma, delta
//   present = true                      # default: true for alpha and beta, false for gamma, delta
//   unit_id = 1                         # Modbus unit id 1–247 (default: 1, 2, 3, 4 in axis order)
//   counts_per_degree = 27.7778         # 10,000 counts per revolution
//   zero_offset_deg = 0                 # stage reading at geometry.md's model angle 0
//   sign = 1                            # −1: the stage turns against geometry.md's axis
//   min_deg = 0                         # travel (defaults: α 0…90, β −180…180, γ −180…180,
//   max_deg = 90                        #   δ 0…180; δ's limits bind a manual detector too)
//   speed_deg_s = 10
//
//   [sample]
//   white_reflectance = 0.99            # ρw of the white standard (the RS-3), in (0, 1]
//   white_reflectance_uncertainty = 0.0058  # u(ρw), k = 1, 0 … 0.5 (default 0.01/√3: ± 1 %)
//
//   [uncertainty]                       # each sample reading's budget (docs/uncertainty.md)
//   enabled = true                      # false: readings are stored "not estimated"
//   wavelength_nm = 1.155               # u(Δλ), 0 … 10 (the PR-650's ±2 nm as rectangular)
//   stray_light = 0                     # u(s), fraction of the white's signal, 0 … 0.1
//   stage_repeatability_deg = 0         # per axis and move, 0 … 5 (+ resolution from the axes)
//   stage_alignment_deg = 0             # per axis, the same at every move, 0 … 5
//   lamp_drift_per_hour = 0.002         # relative, −0.5 … 0.5, used with a single reference
//   meter_full_scale = 0.04             # the meter's noise model (assumed: brdf-sim's detector)
//   meter_full_well_counts = 2e5        #   counts at full scale, > 0
//   meter_read_noise_counts = 20        #   ≥ 0
//   meter_adaptive_fill = 0.5           #   fill adaptive integration aims at, (0, 1]
//   meter_gain_repeatability = 0        #   relative, per measurement, 0 … 0.2
//
//   [rig]
//   name = "rig-a"                      # names the sessions this rig records (default: host name)
//   time_scale = 8                      # a simulated rig: brdf-sim's --time-scale (default 1),
//                                       #   so that estimates and ETAs are the simulator's
//
//   [archive]                           # optional: ship everything recorded to a lab PostgreSQL
//   credentials = "/etc/brdfd/archive.conninfo"  # file holding a libpq conninfo (host, dbname,
//                                       #   user, password, sslmode …); never put it in this file
//   batch_readings = 200                # readings per archive transaction
//   retry_ms = 2000                     # wait before reconnecting after a failure
//
//   [[auth.tokens]]                     # none: the API needs no token (bind to localhost!)
//   name = "lab-pc"
//   token = "at least 16 characters"
//   role = "operator"                   # "operator" (everything) or "analyst" (read only)
//
//   [log]
//   level = "info"                      # trace, debug, info, warn, error, critical, off
//
//   [web]                               # the browser console (web_gateway.h); off by default
//   listen = "127.0.0.1:8080"           # host:port (port 0: any free port); TLS from [server.tls]
//   root = "/usr/share/brdfd/web"       # the built front end (default: installed, else build tree)
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/plan/rig_description.h"
#include "core/status.h"
#include "drivers/pr650/quality_codes.h"

namespace brdf::daemon {

struct TlsConfig {
  std::string cert;       // PEM certificate chain file
  std::string key;        // PEM private key file
  std::string client_ca;  // PEM CA bundle; set: clients must present a certificate it signed
};

struct ServerConfig {
  std::string listen = "127.0.0.1:50051";
  std::optional<TlsConfig> tls;  // unset: plaintext
  // Interpolate's loop threads (daemon/api/interpolate_loop.h); 0: one per two cores (1–8).
  int interpolate_threads = 0;
  // CPUs the loop threads are pinned to, round robin (thread i on cpus[i % size]); empty: not
  // pinned. Gives the loop a core of its own, away from clients and the session's threads.
  std::vector<int> interpolate_cpus;
  // Open streams (WatchSession, StreamReadings, Export, InterpolateBatch, health Watch,
  // reflection) brdfd holds at once (daemon/rpc/stream_registry.h): per token, per role, and for
  // calls without a token. A stream beyond a cap fails with RESOURCE_EXHAUSTED naming the key.
  int max_streams_per_token = 64;
  int max_streams_analyst = 1024;
  int max_streams_operator = 256;
  int max_streams_unauthenticated = 64;
  // A stream whose client has read nothing for this long (one message waiting to be sent the
  // whole time) is cancelled, freeing what it holds (an export's file).
  int stream_stall_timeout_s = 60;
  // The heavy calls' memory budget, MB (daemon/rpc/memory_budget.h): InterpolateBatch, Export and
  // RenderAppearance reserve what they will hold; a call that would take the reservations beyond
  // it, or that arrives while brdfd's resident memory is beyond it, fails with RESOURCE_EXHAUSTED
  // naming the key.
  int memory_budget_mb = 2048;
};

struct StorageConfig {
  std::string database = "/var/lib/brdfd/brdfd.db";
};

// [index]: the interpolation index cache (daemon/index/cache.h), least recently queried session
// out first. A cached paper-grid session (2,112 sample readings of 101 bands with their
// uncertainty budgets, one octant BRDF index) holds roughly 25 MB.
struct IndexConfig {
  int max_sessions = 8;  // sessions kept, 1–1024
  int max_mb = 512;      // memory of their samples, budgets and indexes, MB, 16–1048576
};

// [export]: the interpolants Data.Export keeps for grid, MERL and RGL exports (the session copy,
// its chosen index, the Delaunay fallback and the fitted model; daemon/api/export_cache.h), least
// recently used out first, so that the next export of the same session and settings starts at
// once. A kept paper-grid session (2,112 readings of 101 bands) holds roughly 45 MB of resident
// memory; the analysts' repeated exports of the current session keep about one entry per session.
struct ExportConfig {
  int max_entries = 4;  // interpolants kept, 1–1024
  // Their estimated memory, MB, 1–1048576; 0 (the default): half of [server] memory_budget_mb.
  int max_mb = 0;
};

// The meters brdfd drives, by [meter] model.
enum class MeterModel { kPr650, kPr655, kPr670, kCs2000, kCs2000A, kCs3000 };
// "pr650" … "cs3000" (the configuration's names) and "PR-650" … "CS-3000" (the meters' own).
const char* MeterModelKey(MeterModel model);
const char* MeterModelName(MeterModel model);
std::optional<MeterModel> ParseMeterModel(std::string_view key);
// The driver family: the PR-650's own, the PR-655/670's letter commands, the CS-2000's.
enum class MeterFamily { kPr650, kPr670, kCs2000 };
MeterFamily FamilyOf(MeterModel model);

struct MeterConfig {
  MeterModel model = MeterModel::kPr650;
  std::string port = "/dev/ttyUSB0";
  int baud = 9600;
  bool hardware_flow_control = false;
  int pacing_ms = 100;
  int quiet_gap_ms = 50;
  int reply_timeout_ms = 2000;
  int measurement_timeout_ms = 30000;
  int wake_attempts = 5;
  bool measure_with_spectrum = true;
  int rts_settle_ms = 1000;        // wake-up: wait after RTS is raised again (manual: > 0.5 s)
  int char_gap_ms = 50;            // PR-655/670: pause after each character of a command
  std::string nd_filter = "auto";  // CS-2000/3000: the internal ND filter ("off", "on", "auto")
  // For plan-time estimates only (core/plan/timing.h): the meter's own time per reading beyond
  // integration and transfer, and the integration it is expected to choose when the plan says
  // adaptive, by kind of reading (the white reference is bright, a dark reading runs to 6 s).
  int overhead_ms = 300;
  int adaptive_reference_ms = 2000;
  int adaptive_dark_ms = 6000;
  int adaptive_sample_ms = 2000;
  // Rules that replace the driver's defaults for these quality codes (0–99).
  std::map<int, drivers::pr650::QualityRule> quality_overrides;
};

struct AxisSettings {
  bool present = false;
  int unit_id = 1;
  double counts_per_degree = 10000.0 / 360.0;
  double zero_offset_deg = 0;
  double sign = 1;
  double min_deg = -180;
  double max_deg = 180;
  double speed_deg_s = 10;
};

struct StageConfig {
  std::string transport = "tcp";   // "tcp" or "rtu"
  std::string host = "127.0.0.1";  // tcp (from address)
  int port = 502;                  // tcp (from address)
  std::string device;              // rtu
  int baud = 115200;               // rtu
  char parity = 'E';               // rtu
  std::string profile = "az";      // "az", "leadshine", "moons"
  std::string profile_file;        // a lab's profile file; replaces `profile` (issue 21)
  int response_timeout_ms = 500;
  int busy_window_ms = 3000;    // exception 04/06: retry with back-off this long (issue 21)
  int reconnect_max_ms = 1000;  // longest wait between stage reconnection attempts
  bool detector_arm_motorized = false;
  AxisSettings alpha{true, 1, 10000.0 / 360.0, 0, 1, 0, 90, 10};
  AxisSettings beta{true, 2, 10000.0 / 360.0, 0, 1, -180, 180, 20};
  AxisSettings gamma{false, 3, 10000.0 / 360.0, 0, 1, -180, 180, 20};
  AxisSettings delta{false, 4, 10000.0 / 360.0, 0, 1, 0, 180, 10};
};

struct SampleConfig {
  double white_reflectance = 0.99;
  // u(ρw), standard uncertainty (k = 1): the paper's 99 % ± 1 % read as a rectangular bound,
  // 0.01 / √3 (docs/uncertainty.md, "The white standard"). A plan's sample block may override it.
  double white_reflectance_uncertainty = 0.0057735026918962576;
};

// [uncertainty]: the configured terms of each sample reading's budget (docs/uncertainty.md). The
// meter's noise-model defaults are brdf-sim's detector: assumptions for a real meter.
struct UncertaintyConfig {
  bool enabled = true;                        // estimate and store a budget with each sample
  double wavelength_nm = 1.1547005383792515;  // u(Δλ): the PR-650's ±2 nm, rectangular
  double stray_light = 0;                     // u(s), a fraction of the white's net signal
  double stage_repeatability_deg = 0;         // per axis, each move; the resolution is added from
                                              //   [stage.axes.*] counts_per_degree
  double stage_alignment_deg = 0;             // per axis, the same at every move
  std::optional<double> lamp_drift_per_hour;  // with a single reference; unset: not estimated
  double meter_full_scale = 0.04;  // W·m⁻²·sr⁻¹·nm⁻¹·s that fills the detector
  double meter_full_well_counts = 2e5;
  double meter_read_noise_counts = 20;
  double meter_adaptive_fill = 0.5;
  double meter_gain_repeatability = 0;  // relative, per measurement, not reduced by averaging
};

struct RigConfig {
  std::string name;  // empty: the host name (RigName)
  // How many times faster than real devices the rig's run (brdf-sim --time-scale); 1 for a real
  // rig. The timing model divides device times by it: plan summaries, ETAs.
  double time_scale = 1;
};

// [archive]: present when `credentials` is not empty.
struct ArchiveConfig {
  std::string credentials;  // path of the file holding the libpq conninfo
  int batch_readings = 200;
  int retry_ms = 2000;
  bool enabled() const { return !credentials.empty(); }
};

enum class Role { kOperator, kAnalyst };
const char* RoleName(Role role);  // "operator", "analyst"

struct TokenConfig {
  std::string name;
  std::string token;
  Role role = Role::kAnalyst;
};

struct LogConfig {
  std::string level = "info";
};

// [web]: the gateway is off while listen is empty.
struct WebConfig {
  std::string listen;
  std::string root;
};

struct Config {
  ServerConfig server;
  StorageConfig storage;
  IndexConfig index;
  ExportConfig exports;  // [export]
  MeterConfig meter;
  StageConfig stage;
  SampleConfig sample;
  UncertaintyConfig uncertainty;
  RigConfig rig;
  ArchiveConfig archive;
  std::vector<TokenConfig> tokens;  // [[auth.tokens]]
  LogConfig log;
  WebConfig web;
};

// Shortest acceptable token, in bytes.
inline constexpr std::size_t kMinTokenLength = 16;
// Larger configuration files are refused unread.
inline constexpr std::size_t kMaxConfigBytes = 1024 * 1024;
// CPU numbers in [server] interpolate_cpus are below this (glibc's CPU_SETSIZE).
inline constexpr int kMaxCpuIndex = 1024;

// Parses TOML text. `source` names it in messages (the file's path). kConfigurationError listing
// every problem, one per line, each with its line, key and reason.
Result<Config> ParseConfig(std::string_view toml_text, std::string_view source = "config");

// Reads and parses a file. kNotFound / kIoError when it cannot be read; else as ParseConfig.
Result<Config> LoadConfig(const std::string& path);

// [rig] name, else the host name ("rig" when even that is unknown).
std::string RigName(const Config& config);

// What core/plan needs to know about this rig: motorized axes, travel, speeds, the convention
// (zero offsets and signs), the meter's transfer time at the configured baud rate, its overhead
// per reading and the adaptive integration times by kind of reading.
plan::RigDescription ToRigDescription(const Config& config);

}  // namespace brdf::daemon
