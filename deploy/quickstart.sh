#!/usr/bin/env bash
# The README's main job. On a fresh Debian 12 machine it installs what is missing, builds, and runs
# a short measurement session end to end on a simulated rig:
#   1. starts brdf-sim (a PR-650 on a pty and a Modbus stage, time-scaled) and brdfd, with a
#      generated configuration and random tokens in ./run/ (gitignored);
#   2. submits examples/plans/demo.json (a reduced version of the paper's grid) and starts it;
#   3. shows live progress (brdfctl watch), confirming the operator's prompts; the manual actions
#      (white standard in, shutter closed, sample back) are done on the simulator, as an operator
#      would do them on the real rig;
#   4. prints the interpolated spectrum at a direction between the samples, next to the spectra
#      and weights of the readings it blends;
#   5. leaves brdfd and brdf-sim running and says how to use and stop them, and prints the URL
#      of the web console (operator console and explorer in the browser).
# Running it again stops what the previous run started (pid files in ./run/) and starts afresh.
#
# Usage: deploy/quickstart.sh [--no-build]   build (unless --no-build) and run the live demo
#        deploy/quickstart.sh --stop         stop the brdfd and brdf-sim this script started
#        deploy/quickstart.sh --offline      no daemon: the offline interpolation demo
#                                            (brdf-interp demo; extra arguments go to it)
# Environment: BUILD_DIR (default ./build), RUN_DIR (default ./run), JOBS (build jobs, default:
# number of cores), QUICKSTART_WEB_PORT (the web console's first choice of port, default 8080),
# QUICKSTART_TIME_SCALE (how much faster the simulated rig runs; default 8, so
# the demo takes about a minute), QUICKSTART_PORT (brdfd's first choice of port, default 50051).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
run="${RUN_DIR:-$root/run}"
jobs="${JOBS:-$(nproc)}"
time_scale="${QUICKSTART_TIME_SCALE:-8}"
first_port="${QUICKSTART_PORT:-50051}"
first_web_port="${QUICKSTART_WEB_PORT:-8080}"

# shellcheck source=deploy/lib.sh
source "$root/deploy/lib.sh"
resolve_build_and_run

# A direction between the demo grid's samples (θi, θo, φ in degrees; φ = 180 is the specular
# side): interpolated at the end.
query_theta_i=35
query_theta_o=40
query_phi=40

if [[ -t 1 ]]; then
  say() { printf '\n\033[1mquickstart: %s\033[0m\n' "$*"; }
else
  say() { printf '\nquickstart: %s\n' "$*"; }
fi
die() {
  printf 'quickstart: %s\n' "$*" >&2
  exit 1
}

# --- stopping what a previous run started -------------------------------------------------------

# Stops the process in $run/<name>.pid if it is still that program (a pid the system reused for
# something else is left alone), then removes the pid file.
stop_one() {
  local name="$1" pidfile="$run/$1.pid" pid exe i
  [[ -f "$pidfile" ]] || return 0
  pid="$(cat "$pidfile" 2>/dev/null || true)"
  rm -f "$pidfile"
  [[ "$pid" =~ ^[0-9]+$ ]] || return 0
  exe="$(readlink "/proc/$pid/exe" 2>/dev/null || true)"
  if [[ "$(basename "${exe% (deleted)}")" != "$name" ]]; then
    return 0 # already gone, or the pid now belongs to another program
  fi
  echo "quickstart: stopping $name (pid $pid)"
  kill -TERM "$pid" 2>/dev/null || return 0
  for ((i = 0; i < 150; i++)); do # brdfd pauses its session first: up to ~10 s
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.1
  done
  echo "quickstart: $name (pid $pid) did not stop in 15 s; killing it"
  kill -KILL "$pid" 2>/dev/null || true
}

stop_all() {
  stop_one brdfd # first: it must not see its devices vanish under a session
  stop_one brdf-sim
}

# --- helpers -----------------------------------------------------------------------------------

# Starts "$@" in its own session (it outlives this script and a closed terminal), writing its pid
# to $run/<name>.pid, stdout to $run/<name>.out and stderr to $run/<name>.log.
start_detached() {
  local name="$1"
  shift
  : >"$run/$name.out"
  # shellcheck disable=SC2016 # $$ and $@ are the inner shell's
  setsid bash -c 'echo $$ >"$0"; exec "$@"' "$run/$name.pid" "$@" \
    >"$run/$name.out" 2>"$run/$name.log" </dev/null &
}

# Waits up to $3 seconds for a line matching $2 in $run/$1.out; fails with the log's tail.
wait_for_line() {
  local name="$1" pattern="$2" seconds="$3" i pid
  for ((i = 0; i < seconds * 10; i++)); do
    if grep -q "$pattern" "$run/$name.out" 2>/dev/null; then return 0; fi
    pid="$(cat "$run/$name.pid" 2>/dev/null || true)"
    if [[ -n "$pid" ]] && ! kill -0 "$pid" 2>/dev/null; then break; fi
    sleep 0.1
  done
  echo "quickstart: $name did not start; the end of $run/$name.log:" >&2
  tail -n 20 "$run/$name.log" >&2 || true
  exit 1
}

port_busy() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

random_token() { od -An -N24 -tx1 /dev/urandom | tr -d ' \n'; }

# --- modes -------------------------------------------------------------------------------------

mode=demo
build_it=1
offline_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --stop) mode=stop ;;
    --offline) mode=offline ;;
    --no-build) build_it=0 ;;
    -h | --help)
      awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
      exit 0
      ;;
    *)
      if [[ "$mode" == offline ]]; then
        offline_args+=("$1")
      else
        die "unknown argument $1 (see --help)"
      fi
      ;;
  esac
  shift
done

if [[ "$mode" == stop ]]; then
  stop_all
  echo "quickstart: stopped (the database and logs stay in $run)"
  exit 0
fi

if [[ $build_it -eq 1 ]]; then
  "$root/deploy/install-deps.sh"
  say "configuring and building in $build (the first build takes several minutes)"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  if [[ "$mode" == offline ]]; then
    cmake --build "$build" -j "$jobs" --target brdf-interp
  else
    cmake --build "$build" -j "$jobs" --target brdfd brdf-sim brdfctl
    # The web console's front end (a target only when node and npm are there).
    cmake --build "$build" -j "$jobs" --target brdf_web 2>/dev/null ||
      echo "quickstart: the web console's front end was not built (node/npm missing?); the demo goes on"
  fi
fi

if [[ "$mode" == offline ]]; then
  # The paper's octant interpolation on the paper's grid, from a synthetic sample, checked
  # against the sample's true BRDF; no daemon, no rig.
  exec "$build/tools/brdf-interp/brdf-interp" demo "${offline_args[@]}"
fi

for binary in "$brdfd" "$sim" "$ctl"; do
  [[ -x "$binary" ]] || die "$binary is missing; run without --no-build"
done

# --- the run directory -------------------------------------------------------------------------

mkdir -p "$run"
chmod 700 "$run"
stop_all

# Tokens survive re-runs, so that shells which exported them keep working.
umask 077
[[ -s "$run/operator.token" ]] || random_token >"$run/operator.token"
[[ -s "$run/analyst.token" ]] || random_token >"$run/analyst.token"
operator_token="$(cat "$run/operator.token")"
analyst_token="$(cat "$run/analyst.token")"
umask 022

# Each demo starts from an empty database; the previous one is kept once (brdfd.previous.db,
# replaced by the next run). A database with an unfinished session (queued, running, paused,
# waiting for the operator: e.g. after a crash or --stop) is never replaced: it is kept under a
# name of its own, which no later run touches, and the script says how to carry on with it.
unfinished_sessions() {
  sqlite3 -readonly "$1" "SELECT group_concat(id || ' (' || state || ')', ', ') FROM sessions
    WHERE state IN ('queued', 'running', 'pausing', 'paused', 'awaiting_operator');" 2>/dev/null
}
if [[ -f "$run/brdfd.db" ]]; then
  unfinished="$(unfinished_sessions "$run/brdfd.db" || true)"
  if [[ -n "$unfinished" ]]; then
    kept="$run/brdfd.kept-$(date +%Y%m%d-%H%M%S).db"
    for suffix in "" -wal -shm; do
      if [[ -f "$run/brdfd.db$suffix" ]]; then mv -f "$run/brdfd.db$suffix" "$kept$suffix"; fi
    done
    say "the previous database holds unfinished session(s) $unfinished: kept as $kept"
    cat <<EOF
  This run starts a new database; nothing deletes the kept one. To carry on with those sessions
  instead: deploy/quickstart.sh --stop, set database = "$kept" in $run/brdfd.toml,
  start brdfd again on it (README, "Starting brdfd again") and brdfctl resume <id>.
EOF
  fi
fi
for suffix in "" -wal -shm; do
  if [[ -f "$run/brdfd.db$suffix" ]]; then mv -f "$run/brdfd.db$suffix" "$run/brdfd.previous.db$suffix"; fi
done

# --- the simulated rig -------------------------------------------------------------------------

say "starting the simulated rig (brdf-sim, ${time_scale}x faster than a real rig)"
# --wake-window 0: the simulated PR-650 accepts remote mode at any time (a real one only within
# seconds of power-on; brdfd then asks for a power cycle).
start_detached brdf-sim "$sim" --time-scale "$time_scale" --seed 1 --modbus-port 0 \
  --pr650-link "$run/pr650" --wake-window 0 --log-level warn
wait_for_line brdf-sim '^ready' 20
modbus="$(awk '$1 == "modbus-tcp" { print $2 }' "$run/brdf-sim.out")"
pr650="$(awk '$1 == "pr650" { print $2 }' "$run/brdf-sim.out")"
echo "quickstart: PR-650 on $pr650, stage on Modbus TCP $modbus (brdf-sim pid $(cat "$run/brdf-sim.pid"))"

# --- the daemon --------------------------------------------------------------------------------

port="$first_port"
while port_busy "$port"; do
  echo "quickstart: port $port is taken by another program; trying $((port + 1))"
  port=$((port + 1))
  [[ $port -lt $((first_port + 20)) ]] || die "no free port in $first_port…$port; set QUICKSTART_PORT"
done
address="127.0.0.1:$port"
web_port="$first_web_port"
while port_busy "$web_port" || [[ "$web_port" == "$port" ]]; do
  web_port=$((web_port + 1))
  [[ $web_port -lt $((first_web_port + 20)) ]] || die "no free port for the web console; set QUICKSTART_WEB_PORT"
done

# The meter's pacing and the stage's settling are shortened by the same factor as the simulated
# time; everything else is deploy/brdfd.example.toml's defaults (see that file for every key).
cat >"$run/brdfd.toml" <<EOF
# Generated by deploy/quickstart.sh for the simulated rig; deploy/brdfd.example.toml explains
# every key.
[server]
listen = "$address"

[storage]
database = "$run/brdfd.db"

[meter]
port = "$run/pr650"
pacing_ms = 10
quiet_gap_ms = 20
# brdf-sim's meter, for the estimates (validate, the ETA): 1 s of its own per measurement, and
# the integration its adaptive mode picks by kind of reading (docs/pr650.md, "How long a reading
# takes").
overhead_ms = 1000
adaptive_reference_ms = 150
adaptive_dark_ms = 6000
adaptive_sample_ms = 650

[meter.quality]
# A dark reading (lamp shuttered) is weak by nature: the meter reports quality 10. Keep such
# readings, flagged, instead of retrying them into a fault.
"10" = "accept_and_flag"

[stage]
transport = "tcp"
address = "$modbus"
detector_arm_motorized = true   # brdf-sim has a motorized detector arm (δ, unit 4)

[stage.axes.delta]
present = true

[sample]
white_reflectance = 0.99        # brdf-sim's white standard

[rig]
time_scale = $time_scale        # brdf-sim's --time-scale: estimates and ETAs are the simulator's

[[auth.tokens]]
name = "quickstart-operator"
token = "$operator_token"
role = "operator"

[[auth.tokens]]
name = "quickstart-analyst"
token = "$analyst_token"
role = "analyst"

[web]
listen = "127.0.0.1:$web_port"   # the web console (operator console and explorer)

[log]
level = "info"
EOF
chmod 600 "$run/brdfd.toml"

say "starting brdfd on $address"
start_detached brdfd "$brdfd" --config "$run/brdfd.toml" --shutdown-timeout 5
wait_for_line brdfd '^brdfd listening on' 20
echo "quickstart: brdfd pid $(cat "$run/brdfd.pid"), log $run/brdfd.log"
web_url="$(awk '/^brdfd web console on / { print $5 }' "$run/brdfd.out")"
[[ -z "$web_url" ]] || echo "quickstart: web console on $web_url (token: $run/operator.token)"

export BRDF_ADDRESS="$address"
export BRDF_TOKEN="$operator_token"

# The devices connect in the background; wait until both answer.
for ((i = 0; i < 200; i++)); do
  rig="$("$ctl" rig 2>/dev/null || true)"
  if grep -q '^meter: connected' <<<"$rig" && grep -q '^stage: connected' <<<"$rig"; then break; fi
  sleep 0.1
done
"$ctl" rig || true
if ! grep -q '^meter: connected' <<<"$rig" || ! grep -q '^stage: connected' <<<"$rig"; then
  die "the rig did not connect within 20 s; see $run/brdfd.log"
fi

# --- the demo session --------------------------------------------------------------------------

plan="$root/examples/plans/demo.json"
say "validating and submitting $plan"
"$ctl" validate "$plan" --time-scale "$time_scale"
session="$("$ctl" submit "$plan" --start --quiet)"
echo "quickstart: session $session started"

say "measuring (the operator's prompts are confirmed automatically; the white standard, the shutter and the sample are handled on the simulator)"
# What an operator does by hand at each prompt, done on the simulator (brdfctl sim-mount is for
# brdf-sim only).
on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "$modbus")"
if ! "$ctl" watch "$session" --auto-confirm --on-prompt "$on_prompt" --exit-on-pause; then
  echo "quickstart: the demo session did not complete. brdfd and brdf-sim keep running:" >&2
  echo "  BRDF_ADDRESS=$address BRDF_TOKEN=\$(cat $run/operator.token) $ctl get $session" >&2
  echo "  log: $run/brdfd.log; stop both: deploy/quickstart.sh --stop" >&2
  exit 1
fi

say "interpolating at θi ${query_theta_i}°, θo ${query_theta_o}°, φ ${query_phi}° (between the samples), with the paper's octant method"
"$ctl" interpolate "$session" --theta-i "$query_theta_i" --theta-o "$query_theta_o" \
  --phi "$query_phi" --explain --every 5 ||
  echo "quickstart: (no spectrum there; try other angles with brdfctl interpolate)"

# --- figures -----------------------------------------------------------------------------------
# The Python analysis client (clients/python) draws the paper-style figures of the demo session
# into $run/figures/: Figure 7 (the readings in (α, β, δ) and (θi, θo, φ) with the query and its
# enclosing tetrahedron), Figure 8 (the interpolated spectrum with its vertex spectra) at the
# direction interpolated above, and a polar plot in the plane of incidence. It reads the analyst
# token from its file. Debian's python3 (/usr/bin/python3) has numpy, matplotlib and grpcio;
# another python3 first on PATH (a venv) may not.
figures_script="$root/clients/python/examples/quickstart_figures.py"
python=/usr/bin/python3
[[ -x "$python" ]] || python=python3
figures=""
if [[ -f "$figures_script" ]]; then
  say "writing figures to $run/figures"
  rm -f "$run/figures/fig7.png" "$run/figures/fig8.png" "$run/figures/polar.png"
  if "$python" "$figures_script" --address "$address" --token-file "$run/analyst.token" \
    --session "$session" --out "$run/figures" \
    --query "$query_theta_i" "$query_theta_o" "$query_phi"; then
    figures="$run/figures"
  else
    echo "quickstart: the figures failed (the session and the daemon are fine)"
  fi
fi

# --- what now ----------------------------------------------------------------------------------

example() { printf '  %-62s # %s\n' "$1" "$2"; }
cat <<EOF

quickstart: done. brdfd and the simulated rig keep running.

Talk to the daemon (operator token; $run/analyst.token holds a read-only one):
  export BRDF_ADDRESS=$address
  export BRDF_TOKEN=\$(cat $run/operator.token)
  export PATH="$build/tools/brdfctl:\$PATH"
  export BRDF_SIM_MODBUS=$modbus   # the simulator's Modbus address (clients/python/README.md)

EOF
example "brdfctl list" "sessions, newest first"
example "brdfctl get $session" "the demo session"
example "brdfctl readings $session --kind sample" "its readings, pose by pose"
example "brdfctl interpolate $session --theta-i 40 --theta-o 35 --phi 45" "BRDF, the paper's method"
example "brdfctl interpolate $session --theta-i 40 --theta-o 35 --phi 45 --method delaunay" "Qhull"
example "brdfctl rig" "devices, live pose, meter serial"
example "brdfctl validate examples/plans/pose-list.json" "check a plan"
example "brdfctl submit examples/plans/pose-list.json --start -q" "run it (prints its id)"
example "brdfctl watch <id> --on-prompt \"brdfctl sim-mount from-prompt --modbus $modbus\"" \
  "live; y/N at prompts"
example "brdfctl pause <id> [--immediate]; brdfctl resume <id>" "operator verbs"
example "brdfctl abort <id> --reason \"lamp flickers\"" "stop for good (data kept)"
example "brdfctl export $session csv -o demo.csv" "readings, units in the header"
example "brdfctl export $session grid --steps 5 -o demo.npy" "regular grid (+ demo.npy.json)"
example "brdfctl export $session merl -o demo.binary" "MERL BRDF file (RGB, D65)"
if [[ -n "$web_url" ]]; then
  cat <<EOF

In the browser: $web_url
  sign in with the token in $run/operator.token (operator) or $run/analyst.token (read only)
EOF
fi
cat <<EOF

Files: $run/brdfd.toml (configuration), $run/brdfd.db (data),
       $run/brdfd.log and $run/brdf-sim.log (logs)${figures:+
Figures: $figures/fig7.png (Figure 7: samples, query, tetrahedron),
         $figures/fig8.png (Figure 8: interpolated spectrum and its vertices),
         $figures/polar.png (BRDF in the plane of incidence)}
Stop both: deploy/quickstart.sh --stop
EOF
