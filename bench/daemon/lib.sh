# shellcheck shell=bash
# Shared by bench/daemon's scripts (sourced, not run): fresh bearer tokens, the work directory
# and the processes to stop on exit, waiting for a line in a log or for the rig to connect, and
# brdfd's configuration for a rig on brdf-sim.

# shellcheck disable=SC2034  # used by the scripts that source this file
operator_token="bench-operator-$(od -An -N8 -tx1 /dev/urandom | tr -d ' \n')"
analyst_token="bench-analyst-$(od -An -N8 -tx1 /dev/urandom | tr -d ' \n')"

# Makes the work directory (mktemp -d on template $1) in `work`, starts `pids` empty, and traps
# EXIT to bench_cleanup: a script adds the pid of each process it starts to `pids`, and any other
# directory to remove on exit to `cleanup_dirs`.
bench_workdir_and_cleanup() {
  work="$(mktemp -d "$1")"
  pids=()
  cleanup_dirs=()
  trap bench_cleanup EXIT
}

# Like bench_workdir_and_cleanup, but with a directory the user named ($1, e.g. from --keep DIR):
# the work happens there and stays afterwards (BENCH_KEEP=1). An empty $1 falls back to a
# temporary directory on template $2.
bench_workdir_kept_or_temporary() {
  if [[ -z "$1" ]]; then
    bench_workdir_and_cleanup "$2"
    return
  fi
  mkdir -p "$1"
  work="$(cd "$1" && pwd)"
  pids=()
  cleanup_dirs=()
  trap bench_cleanup EXIT
  BENCH_KEEP=1
}

# The rig's three programs in build directory $2: builds them and the targets $3… (-j2, on
# stderr) unless BENCH_NO_BUILD=1, sets `brdfd`, `sim` and `ctl`, and exits 77 (skipped) naming a
# missing one; $1 names the calling script in that message.
bench_rig_programs() {
  local script="$1" dir="$2" binary
  shift 2
  if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
    echo "== building brdfd, brdf-sim, brdfctl${*:+ and $*} (-j2)" >&2
    cmake --build "$dir" -j2 --target brdfd brdf-sim brdfctl "$@" >&2
  fi
  brdfd="$dir/daemon/brdfd"
  sim="$dir/tools/brdf-sim/brdf-sim"
  ctl="$dir/tools/brdfctl/brdfctl"
  for binary in "$brdfd" "$sim" "$ctl"; do
    [[ -x "$binary" ]] || { echo "$script: $binary is missing; build it (or unset BENCH_NO_BUILD)" >&2; exit 77; }
  done
}

# Debian's python3, which has numpy and grpcio (another python3 first on PATH, a venv, may not),
# in `python`, and the Python client's stubs of build directory $1 in BRDF_PY_STUBS.
bench_python_with_stubs() {
  python=/usr/bin/python3
  [[ -x "$python" ]] || python=python3
  export BRDF_PY_STUBS="${BRDF_PY_STUBS:-$1/clients/python/stubs}"
}

# Stops every process in `pids` (SIGTERM, then waits for each), removes `cleanup_dirs`, and removes
# `work` unless BENCH_KEEP=1.
bench_cleanup() {
  local p
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  if ((${#cleanup_dirs[@]} > 0)); then rm -rf "${cleanup_dirs[@]}"; fi
  if [[ "${BENCH_KEEP:-0}" == 1 ]]; then echo "kept: $work" >&2; else rm -rf "$work"; fi
}

# Stops one process now (SIGTERM, then waits for it); bench_cleanup stops the rest on exit.
stop_pid() { kill -TERM "$1" 2>/dev/null || true; wait "$1" 2>/dev/null || true; }

# Waits up to $3 s for a line matching $2 in file $1.
wait_line() {
  local i
  for ((i = 0; i < $3 * 10; i++)); do
    if grep -q "$2" "$1" 2>/dev/null; then return 0; fi
    sleep 0.1
  done
  echo "bench/daemon: no '$2' in $1 after $3 s" >&2
  return 1
}

# Waits up to $2 s (default 20) until `$1 rig` (brdfctl, with BRDF_ADDRESS and BRDF_TOKEN set)
# shows both the meter and the stage connected; the devices connect in the background.
wait_for_rig_connected() {
  local i rig=""
  for ((i = 0; i < ${2:-20} * 10; i++)); do
    rig="$("$1" rig 2>/dev/null || true)"
    if grep -q '^meter: connected' <<<"$rig" && grep -q '^stage: connected' <<<"$rig"; then
      return 0
    fi
    sleep 0.1
  done
  echo "bench/daemon: the rig at ${BRDF_ADDRESS:-?} did not connect within ${2:-20} s (brdfctl rig:" \
    "$(tr '\n' ' ' <<<"$rig")); see brdfd's log" >&2
  return 1
}

# Starts brdf-sim at time scale $2 (log level $3, its PR-650 on the link $1/pr650) and brdfd on
# the configuration write_config writes to $1/brdfd.toml (database $1/brdfd.db), their output in
# $1/{sim,brdfd}.{out,log}; waits until the rig is connected. Uses the script's `sim`, `brdfd` and
# `ctl`; sets sim_pid, brdfd_pid (both added to `pids`) and modbus (the simulator's host:port), and
# exports BRDF_ADDRESS and BRDF_TOKEN (the operator's). A script may set sim_seed (brdf-sim's
# --seed; default 1) and the array sim_extra_args (more brdf-sim flags, e.g. --material FILE).
# shellcheck disable=SC2154  # sim, brdfd and ctl are the sourcing script's
start_rig_on_sim() {
  local dir="$1" scale="$2" level="$3"
  "$sim" --time-scale "$scale" --seed "${sim_seed:-1}" --modbus-port 0 --pr650-link "$dir/pr650" \
    --wake-window 0 --log-level "$level" ${sim_extra_args[@]+"${sim_extra_args[@]}"} \
    >"$dir/sim.out" 2>"$dir/sim.log" </dev/null &
  sim_pid=$!
  pids+=("$sim_pid")
  wait_line "$dir/sim.out" '^ready' 20
  modbus="$(awk '$1 == "modbus-tcp" { print $2 }' "$dir/sim.out")"
  write_config "$dir/brdfd.db" "$dir/pr650" "$modbus" >"$dir/brdfd.toml"
  "$brdfd" --config "$dir/brdfd.toml" --shutdown-timeout 3 >"$dir/brdfd.out" 2>"$dir/brdfd.log" \
    </dev/null &
  brdfd_pid=$!
  pids+=("$brdfd_pid")
  wait_line "$dir/brdfd.out" '^brdfd listening on' 20
  export BRDF_ADDRESS
  BRDF_ADDRESS="$(awk '/^brdfd listening on/ { print $4 }' "$dir/brdfd.out")"
  export BRDF_TOKEN="$operator_token"
  wait_for_rig_connected "$ctl"
}

# Records the plan $1 on the rig start_rig_on_sim started (its prompts answered by mounting on the
# simulator, its log in $2): submits, starts and watches it until it ends or pauses; sets
# `session` to its id. Uses the script's `ctl` and start_rig_on_sim's `modbus`.
record_session_on_sim() {
  local plan="$1" log="$2" on_prompt
  session="$("$ctl" submit "$plan" --start --quiet)"
  on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "$modbus")"
  "$ctl" watch "$session" --auto-confirm --on-prompt "$on_prompt" --exit-on-pause \
    >"$log" 2>&1 </dev/null
}

# brdfd's configuration on stdout, with both tokens: $1 database, $2 meter port, $3 Modbus
# host:port, $4 more [server] lines. A script may set config_axis_speed (deg/s of α, β and δ;
# unset: the defaults), config_extra (TOML appended at the end, in tables of its own) and
# config_real_meter=1 (the [meter] timing for the estimates left at brdfd's defaults, a real
# PR-650's, instead of brdf-sim's meter: estimates then say what the plan takes on a real rig).
write_config() {
  cat <<EOT
[server]
listen = "127.0.0.1:0"
${4:-}
[storage]
database = "$1"
[meter]
port = "$2"
pacing_ms = 5
quiet_gap_ms = 10
EOT
  if [[ "${config_real_meter:-0}" != 1 ]]; then
    cat <<EOT
# brdf-sim's meter, for the estimates (docs/pr650.md, "How long a reading takes")
overhead_ms = 1000
adaptive_reference_ms = 150
adaptive_dark_ms = 6000
adaptive_sample_ms = 650
EOT
  fi
  cat <<EOT
[stage]
transport = "tcp"
address = "$3"
detector_arm_motorized = true
EOT
  if [[ -n "${config_axis_speed:-}" ]]; then
    printf '[stage.axes.alpha]\nspeed_deg_s = %s\n[stage.axes.beta]\nspeed_deg_s = %s\n' \
      "$config_axis_speed" "$config_axis_speed"
    printf '[stage.axes.delta]\npresent = true\nspeed_deg_s = %s\n' "$config_axis_speed"
  else
    printf '[stage.axes.delta]\npresent = true\n'
  fi
  cat <<EOT
[[auth.tokens]]
name = "bench-operator"
token = "$operator_token"
role = "operator"
[[auth.tokens]]
name = "bench-analyst"
token = "$analyst_token"
role = "analyst"
[log]
level = "warn"
${config_extra:-}
EOT
}

# brdfd's (any process's) resident memory now, kB: VmRSS of /proc/$1/status (0 once it is gone).
rss_kb() { awk '$1 == "VmRSS:" { print $2; found = 1 } END { if (!found) print 0 }' "/proc/$1/status" 2>/dev/null || echo 0; }

# Appends "SECONDS_SINCE_START RSS_KB THREADS FDS" for process $1 to file $2 every $3 s until it
# is stopped (run it in the background) or the process is gone.
sample_rss() {
  local start=$SECONDS
  while [[ -d "/proc/$1" ]]; do
    echo "$((SECONDS - start)) $(rss_kb "$1") $(awk '$1 == "Threads:" { print $2 }' "/proc/$1/status" 2>/dev/null || echo 0) $(find "/proc/$1/fd" -mindepth 1 -maxdepth 1 2>/dev/null | wc -l)" >>"$2"
    sleep "$3"
  done
}
