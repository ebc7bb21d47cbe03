#!/usr/bin/env bash
# The control plane under analyst load (issues 20, 40): PauseSession and GetRigStatus latency on
# an idle brdfd, then with 1,000 analyst streams open (400 WatchSession and 300 StreamReadings read
# as they come, 200 InterpolateBatch and 100 Export never read) and 8 clients calling Interpolate,
# in the same run. Prints one line of key=value figures (bench_control_plane's): the ratios
# loaded ÷ idle (goal: pause_ratio and status_ratio ≤ 3, pause_p99_ratio and status_p99_ratio ≤ 5,
# control_failed=0) and brdfd's VmRSS: idle, at its peak, and BENCH_SETTLE_S (60) after the
# streams ended (goal: rss_growth_mb ≤ 200, rss_left_mb ≤ 50), with the load average at start and
# end (the machine's other work shows there: compare runs by their ratios, not their times).
# The operator's calls come from a process of their own at nice 0, as brdfctl's do; the analysts'
# client threads run at nice 10 (BENCH_OPERATOR_IN_LOAD_PROCESS=1: the operator's calls from the
# analysts' process, as before 2026-12-06). The daemon runs against brdf-sim with a
# 10,000-reading session (bench_storage) for the data calls and a paused session (started, then
# paused at its first prompt) for the verbs.
# Usage: bench/daemon/control_plane.sh [BUILD_DIR] (default: build-bench; builds what it needs
# unless BENCH_NO_BUILD=1). BENCH_STREAMS (default 1000), BENCH_MEMORY_BUDGET_MB ([server]
# memory_budget_mb; default the daemon's), BENCH_KEEP=1 keeps the logs, BENCH_SLOW_MS prints each
# control call slower than that to stderr with its start on CLOCK_MONOTONIC (to set beside
# `perf sched record -k CLOCK_MONOTONIC -p $(pgrep brdfd)`).
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-${BRDF_BENCH_BUILD:-$root/build-bench}}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
streams="${BENCH_STREAMS:-1000}"
if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  if [[ ! -f "$build/build.ninja" && ! -f "$build/Makefile" ]]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  cmake --build "$build" -j2 --target brdfd brdf-sim brdfctl bench_storage \
    bench_control_plane >&2
fi
brdfd="$build/daemon/brdfd"
sim="$build/tools/brdf-sim/brdf-sim"
ctl="$build/tools/brdfctl/brdfctl"
bin="$build/bench/daemon"

# shellcheck source=bench/daemon/lib.sh
source "$here/lib.sh"
bench_workdir_and_cleanup /tmp/brdfd-ctlbench.XXXXXX

echo "== a 10,000-reading session (bench_storage), brdf-sim, brdfd" >&2
"$bin/bench_storage" create --db "$work/bench.db" --readings 10000 >/dev/null
"$sim" --time-scale 10 --seed 1 --modbus-port 0 --wake-window 0 --log-level warn \
  >"$work/sim.out" 2>"$work/sim.log" </dev/null &
pids+=("$!")
wait_line "$work/sim.out" '^ready' 20
modbus="$(awk '$1 == "modbus-tcp" { print $2 }' "$work/sim.out")"
pr650="$(awk '$1 == "pr650" { print $2 }' "$work/sim.out")"
# One analyst token holds all the streams: the per-token cap is raised to let it.
write_config "$work/bench.db" "$pr650" "$modbus" "max_streams_per_token = $((streams + 24))
max_streams_analyst = $((streams + 24))
stream_stall_timeout_s = 600${BENCH_MEMORY_BUDGET_MB:+
memory_budget_mb = $BENCH_MEMORY_BUDGET_MB}" >"$work/brdfd.toml"
"$brdfd" --config "$work/brdfd.toml" >"$work/brdfd.out" 2>"$work/brdfd.log" </dev/null &
brdfd_pid=$!
pids+=("$brdfd_pid")
wait_line "$work/brdfd.out" '^brdfd listening on' 20
address="$(awk '/^brdfd listening on/ { print $4 }' "$work/brdfd.out")"
export BRDF_ADDRESS="$address" BRDF_TOKEN="$operator_token"

cat >"$work/plan.json" <<'EOF'
{"name": "bench: the session the operator pauses",
 "sampleRotation": {"delta": {"start": 20, "stop": 60, "step": 10},
                    "alpha": {"start": 0, "stop": 60, "step": 5}, "beta": {"step": 15}},
 "reference": {"perDetectorPosition": true},
 "measurement": {"integrationMs": 50, "averages": 1}}
EOF
paused="$("$ctl" submit "$work/plan.json" --start --quiet)"
for ((i = 0; i < 200; i++)); do
  if "$ctl" pause "$paused" --immediate >/dev/null 2>&1 &&
    "$ctl" --json get "$paused" 2>/dev/null | grep -q 'SESSION_STATE_PAUSED'; then break; fi
  sleep 0.1
done

echo "== control calls idle, then with $streams analyst streams and 8 Interpolate clients" >&2
# Idle with the data session's index built (one Interpolate, as any analyst's first call): the
# memory figures then compare the streams, not the index cache.
BRDF_TOKEN="$analyst_token" "$ctl" interpolate 1 --theta-i 30 --theta-o 30 --phi 10 >/dev/null ||
  true
sleep 2
load_start="$(cut -d" " -f1-3 /proc/loadavg | tr " " /)"
rss_idle_kb="$(rss_kb "$brdfd_pid")"
sample_rss "$brdfd_pid" "$work/rss.samples" 0.5 &
sampler=$!
pids+=("$sampler")
line="$("$bin/bench_control_plane" --address "$address" --operator-token "$operator_token" \
  --analyst-token "$analyst_token" --pause-session "$paused" --data-session 1 \
  --streams "$streams" ${BENCH_OPERATOR_IN_LOAD_PROCESS:+--operator-in-load-process} \
  ${BENCH_SLOW_MS:+--slow-ms "$BENCH_SLOW_MS"})" || rc=$?
rss_ended_kb="$(rss_kb "$brdfd_pid")"
settle="${BENCH_SETTLE_S:-60}"
sleep "$settle"
stop_pid "$sampler"
rss_peak_kb="$(awk 'BEGIN { m = 0 } $2 > m { m = $2 } END { print m }' "$work/rss.samples")"
rss_settled_kb="$(rss_kb "$brdfd_pid")"
# The memory goal (issue 40): the streams grow RSS by at most 200 MB over idle, and RSS is back
# within 50 MB of idle a minute after they end.
echo "$line rss_idle_mb=$((rss_idle_kb / 1024)) rss_peak_mb=$((rss_peak_kb / 1024))" \
  "rss_growth_mb=$(((rss_peak_kb - rss_idle_kb) / 1024)) rss_at_end_mb=$((rss_ended_kb / 1024))" \
  "rss_after_${settle}s_mb=$((rss_settled_kb / 1024))" \
  "rss_left_mb=$(((rss_settled_kb - rss_idle_kb) / 1024)) loadavg_start=$load_start loadavg_end=$(cut -d' ' -f1-3 /proc/loadavg | tr ' ' /)"
"$ctl" get "$paused" | head -3 >&2
echo "brdfd VmHWM $(awk '$1 == "VmHWM:" { print $2 }' "/proc/$brdfd_pid/status") kB, threads $(awk '$1 == "Threads:" { print $2 }' "/proc/$brdfd_pid/status")" >&2
exit "${rc:-0}"
