#!/usr/bin/env bash
# Figures for a running daemon (issue 6, bench part 3), in one run of about three minutes:
#   1. gRPC Interpolate latency (p50, p99) and throughput, 8 concurrent clients on loopback, while
#      a session records against brdf-sim: (a) querying the recording session itself (its index
#      takes in each new reading), (b) querying a completed 10,000-reading session meanwhile; the
#      load generator drives its 8 clients (8 connections) from one thread (bench_daemon_load
#      --api queue) pinned to the first CPUs (taskset), brdfd's Interpolate loop is pinned to the
#      last one ([server] interpolate_cpus): server and clients each on cores of their own, as
#      when the clients run elsewhere; the session's threads run where the scheduler puts them;
#      (c) as (a) with gRPC's multi-threaded callback client, not pinned, for comparison: its busy
#      threads outnumber the cores, and the tail is the scheduler's 4 ms ticks;
#   2. session time against the physical lower bound, pipelining on and off (same plan, ≥ 500
#      steps, brdf-sim in scaled time with its 9600-baud pacing; bench_session_time);
#   3. readings ingested per second into SQLite (one transaction per reading, synchronous=FULL),
#      on the disk of the temporary folder;
#   4. peak RSS (VmHWM) of brdfd holding a 10,000- and a 50,000-reading session after loading and
#      querying them (sessions written through storage/ by bench_storage, not measured for hours);
#      (d) on the 10k one, nothing pinned: Interpolate p99 ÷ a no-op's p99, both driven by the same
#      8 clients in the same window (bench_daemon_load --noop: every other call the no-op).
# Prints a table at the end. Called by bench/run.sh; runnable alone.
#
# Usage: bench/daemon/run.sh [BUILD_DIR]    (default: $BRDF_BENCH_BUILD, then build-bench)
#   Builds what it needs there (-j2) unless BENCH_NO_BUILD=1. Environment: BENCH_LOAD_SECONDS
#   (default 6 per latency window), BENCH_TIME_SCALE (brdf-sim's for the session-time runs,
#   default 20), BENCH_KEEP=1 keeps the temporary folder (logs, databases).
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-${BRDF_BENCH_BUILD:-$root/build-bench}}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
load_seconds="${BENCH_LOAD_SECONDS:-6}"
time_scale="${BENCH_TIME_SCALE:-20}"

if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  if [[ ! -f "$build/build.ninja" && ! -f "$build/Makefile" ]]; then
    echo "== configuring $build" >&2
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  echo "== building the daemon bench (-j2)" >&2
  cmake --build "$build" -j2 --target brdfd brdf-sim brdfctl bench_session_time \
    bench_daemon_load bench_storage >&2
fi
brdfd="$build/daemon/brdfd"
sim="$build/tools/brdf-sim/brdf-sim"
ctl="$build/tools/brdfctl/brdfctl"
bin="$build/bench/daemon"

# shellcheck source=bench/daemon/lib.sh
source "$here/lib.sh"
bench_workdir_and_cleanup /tmp/brdfd-bench.XXXXXX
# Sessions for the memory figure are written on a tmpfs (their fsyncs are not what is measured).
shm_parent=/dev/shm
[[ -d "$shm_parent" && -w "$shm_parent" ]] || shm_parent="$work"
shm="$(mktemp -d "$shm_parent/brdfd-bench.XXXXXX")"
cleanup_dirs+=("$shm")
config_axis_speed=30
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'

# Starts brdfd on config $1 (log $2); sets brdfd_pid and address.
start_brdfd() {
  "$brdfd" --config "$1" --shutdown-timeout 3 >"$2.out" 2>"$2" </dev/null &
  brdfd_pid=$!
  pids+=("$brdfd_pid")
  wait_line "$2.out" '^brdfd listening on' 20
  address="$(awk '/^brdfd listening on/ { print $4 }' "$2.out")"
}
kb() { awk -v k="$2:" '$1 == k { print $2 }' "/proc/$1/status"; }
field() { tr ' ' '\n' <<<"$1" | awk -F= -v k="$2" '$1 == k { print $2 }'; }

# Cores of their own for brdfd's Interpolate loop (the last CPU) and the load generator (the
# others), when there are at least two.
ncpu="$(nproc)"
loop_pin=""
client_pin=()
if ((ncpu >= 2)); then
  loop_pin="interpolate_cpus = [$((ncpu - 1))]"
  client_pin=(taskset -c "0-$((ncpu - 2))")
fi

echo "brdfd daemon bench — $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) CPUs, build $build"
echo "uptime at start: $(uptime)"

# --- sessions written through storage/ (the memory figure, and the 10k session queried in 1b) ---
echo "== writing 10,000- and 50,000-reading sessions (bench_storage create, on $shm_parent)" >&2
create10k="$("$bin/bench_storage" create --db "$shm/s10k.db" --readings 10000)"
create50k="$("$bin/bench_storage" create --db "$shm/s50k.db" --readings 50000)"

# --- 1. latency while a session records ---------------------------------------------------------
echo "== 1. Interpolate under load while a session records" >&2
"$sim" --time-scale 10 --seed 1 --modbus-port 0 --wake-window 0 --log-level warn \
  >"$work/sim.out" 2>"$work/sim.log" </dev/null &
sim_pid=$!
pids+=("$sim_pid")
wait_line "$work/sim.out" '^ready' 20
modbus="$(awk '$1 == "modbus-tcp" { print $2 }' "$work/sim.out")"
pr650="$(awk '$1 == "pr650" { print $2 }' "$work/sim.out")"
cp "$shm/s10k.db" "$work/live.db"
write_config "$work/live.db" "$pr650" "$modbus" "$loop_pin" >"$work/live.toml"
start_brdfd "$work/live.toml" "$work/live.log"
live_pid=$brdfd_pid
export BRDF_ADDRESS="$address" BRDF_TOKEN="$operator_token"
wait_for_rig_connected "$ctl"
# Long enough to go on recording through both windows (a) and (b): steps_recorded > 0 in each.
cat >"$work/live-plan.json" <<'EOF'
{"name": "bench: recording while queried",
 "sampleRotation": {"delta": {"start": 20, "stop": 60, "step": 10},
                    "alpha": {"start": 0, "stop": 60, "step": 5}, "beta": {"step": 15}},
 "reference": {"perDetectorPosition": true},
 "measurement": {"integrationMs": 50, "averages": 1}}
EOF
live="$("$ctl" submit "$work/live-plan.json" --start --quiet)"
on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "$modbus")"
"$ctl" watch "$live" --auto-confirm --on-prompt "$on_prompt" --exit-on-pause \
  >"$work/watch.out" 2>&1 </dev/null &
watch_pid=$!
pids+=("$watch_pid")
# Until the recording session has some sample readings to interpolate.
for ((i = 0; i < 300; i++)); do
  if "$ctl" interpolate "$live" --theta-i 30 --theta-o 30 --phi 90 >/dev/null 2>&1; then break; fi
  sleep 0.1
done
load_live="$("${client_pin[@]}" "$bin/bench_daemon_load" --address "$address" --token "$analyst_token" \
  --session "$live" --recording "$live" --clients 8 --seconds "$load_seconds" --warmup 1)"
echo "   $load_live" >&2
load_10k="$("${client_pin[@]}" "$bin/bench_daemon_load" --address "$address" --token "$analyst_token" \
  --session 1 --recording "$live" --clients 8 --seconds "$load_seconds" --warmup 2)"
echo "   $load_10k" >&2
load_cb="$("$bin/bench_daemon_load" --address "$address" --token "$analyst_token" \
  --session "$live" --recording "$live" --clients 8 --seconds "$load_seconds" --warmup 1 \
  --api callback)"
echo "   $load_cb" >&2
"$ctl" abort "$live" --reason "bench done" >/dev/null 2>&1 || true
stop_pid "$watch_pid"
stop_pid "$live_pid"
stop_pid "$sim_pid"

# --- 2. session time against the physical bound --------------------------------------------------
# The session databases go on the tmpfs: a commit's fsync is real time and does not scale with the
# simulator (×$time_scale), so on disk it would count 20× too much; part 3 measures it on disk.
echo "== 2. session time vs the physical bound, pipelining on and off (time scale $time_scale)" >&2
session_lines="$(BRDF_SIM_BINARY="$sim" "$bin/bench_session_time" --time-scale "$time_scale" \
  --mode both --work "$shm")"
echo "$session_lines" | sed 's/^/   /' >&2
on_line="$(grep 'pipelining=on' <<<"$session_lines")"
off_line="$(grep 'pipelining=off' <<<"$session_lines")"

# --- 3. SQLite ingest ---------------------------------------------------------------------------
echo "== 3. readings ingested per second (SQLite, synchronous=FULL, $(df --output=source "$work" | tail -1))" >&2
ingest="$("$bin/bench_storage" ingest --db "$work/ingest.db" --seconds 5 --readings 100000)"
echo "   $ingest" >&2

# --- 4. memory of brdfd holding 10k and 50k readings --------------------------------------------
echo "== 4. brdfd's peak RSS holding a session" >&2
declare -A rss_idle rss_peak rss_now
for n in 10k 50k; do
  # No rig: the meter port does not exist and nothing listens on the Modbus port (the daemon
  # starts without its devices and keeps retrying in the background).
  write_config "$shm/s$n.db" "$work/no-such-meter" "127.0.0.1:9" >"$work/mem$n.toml"
  start_brdfd "$work/mem$n.toml" "$work/mem$n.log"
  sleep 0.5
  rss_idle[$n]="$(kb "$brdfd_pid" VmHWM)"
  mem_load="$("$bin/bench_daemon_load" --address "$address" --token "$analyst_token" \
    --session 1 --clients 2 --seconds 2 --warmup 0)"
  rss_peak[$n]="$(kb "$brdfd_pid" VmHWM)"
  rss_now[$n]="$(kb "$brdfd_pid" VmRSS)"
  if [[ $n == 10k ]]; then
    # (d) Interpolate p99 ÷ the no-op's p99, both from the same 8 clients in the same window,
    # nothing pinned (this brdfd has no interpolate_cpus): the ratio holds where absolute times
    # on a shared machine do not.
    load_ratio="$("$bin/bench_daemon_load" --address "$address" --token "$analyst_token" \
      --session 1 --clients 8 --seconds "$load_seconds" --warmup 1 --noop)"
    echo "   (d) $load_ratio" >&2
  fi
  echo "   $n: idle ${rss_idle[$n]} kB, after loading+querying: VmHWM ${rss_peak[$n]} kB, VmRSS ${rss_now[$n]} kB ($mem_load)" >&2
  stop_pid "$brdfd_pid"
done

# --- the table ----------------------------------------------------------------------------------
mb() { awk -v k="$1" 'BEGIN { printf "%.1f MB", k / 1024 }'; }
ms() { awk -v u="$1" 'BEGIN { printf "%.3f ms", u / 1000 }'; }
echo
echo "== brdfd under load (figures for a running daemon)"
printf '%-58s %s\n' "figure" "value"
printf '%-58s %s\n' "----------------------------------------------------------" "-----------------------------"
for which in live 10k callback; do
  line="$load_live"
  label="(a) Interpolate, 8 clients, the recording session: p50"
  if [[ $which == 10k ]]; then line="$load_10k"; label="(b) Interpolate, 8 clients, a 10k-reading session: p50"; fi
  if [[ $which == callback ]]; then
    line="$load_cb"; label="(c) as (a), from gRPC's multi-threaded client: p50"
  fi
  printf '%-58s %s\n' "$label" "$(ms "$(field "$line" p50_us)")"
  printf '%-58s %s\n' "  p99 (target < 1 ms)" "$(ms "$(field "$line" p99_us)")"
  printf '%-58s %s\n' "  p99.9 / max" "$(ms "$(field "$line" p999_us)") / $(ms "$(field "$line" max_us)")"
  printf '%-58s %s\n' "  throughput" "$(field "$line" qps) calls/s ($(field "$line" calls) calls, $(field "$line" errors) errors)"
  printf '%-58s %s\n' "  steps the session recorded meanwhile" "$(field "$line" steps_recorded)"
done
printf '%-58s %s\n' "(d) Interpolate ÷ no-op p99, 8 clients, 10k session, unpinned" "$(field "$load_ratio" p99_ratio) (goal ≤ 1.5)"
printf '%-58s %s\n' "  Interpolate p50 / p99" "$(ms "$(field "$load_ratio" p50_us)") / $(ms "$(field "$load_ratio" p99_us)") ($(field "$load_ratio" calls) calls)"
printf '%-58s %s\n' "  no-op (Interpolate refused before any work) p50 / p99" "$(ms "$(field "$load_ratio" noop_p50_us)") / $(ms "$(field "$load_ratio" noop_p99_us)") ($(field "$load_ratio" noop_calls) calls)"
for line in "$on_line" "$off_line"; do
  mode="$(field "$line" pipelining)"
  printf '%-58s %s\n' "session, pipelining $mode: steps / sample readings" "$(field "$line" steps) / $(field "$line" samples)"
  printf '%-58s %s\n' "  measured (simulated s = wall × $(field "$line" time_scale))" "$(field "$line" measured_sim_s) s (wall $(field "$line" wall_s) s)"
  printf '%-58s %s\n' "  physical lower bound (pipelined executor)" "$(field "$line" bound_s) s"
  printf '%-58s %s\n' "  measured / bound (target ≤ 1.05 with pipelining)" "$(field "$line" ratio)"
  if [[ $mode == off ]]; then
    printf '%-58s %s\n' "  bound of a sequential executor" "$(field "$line" sequential_bound_s) s"
  fi
done
on_s="$(field "$on_line" measured_sim_s)"
off_s="$(field "$off_line" measured_sim_s)"
printf '%-58s %s\n' "pipelining off / on (same plan)" "$(awk -v a="$off_s" -v b="$on_s" 'BEGIN { printf "%.3f", a / b }')"
printf '%-58s %s\n' "SQLite ingest (1 transaction per reading, synchronous=FULL)" "$(field "$ingest" per_s) readings/s ($(field "$ingest" readings) in $(field "$ingest" seconds) s)"
for n in 10k 50k; do
  line="$create10k"
  [[ $n == 50k ]] && line="$create50k"
  printf '%-58s %s\n' "brdfd peak RSS (VmHWM), $n-reading session loaded+queried" "$(mb "${rss_peak[$n]}") (idle $(mb "${rss_idle[$n]}"); db $(awk -v b="$(field "$line" bytes)" 'BEGIN { printf "%.1f MB", b / 1048576 }'))"
done
printf '%-58s %s\n' "  RSS growth 10k → 50k per reading" "$(awk -v a="${rss_peak[10k]}" -v b="${rss_peak[50k]}" 'BEGIN { printf "%.2f kB/reading (raw spectrum: 0.79 kB)", (b - a) / 40000 }')"
echo "uptime at end: $(uptime)"
