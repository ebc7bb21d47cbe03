#!/usr/bin/env bash
# What asking for uncertainties costs the grid export (issue 37, deliverable 6: at most 2× the
# time without): records examples/plans/demo.json on brdf-sim through brdfd (87 sample readings,
# each with its stored budget), then times `brdfctl export SESSION grid` with and without
# --uncertainty in the same run, alternating which goes first, and prints the medians and their
# ratio, and the same for brdfd's CPU time (all its threads, /proc/PID/stat), which a machine
# shared with other work disturbs less than the wall time. Both write float32 .npy files (with
# --uncertainty four of them).
#
# Usage: bench/uncertainty/grid_cost.sh [BUILD_DIR]   (default ./build; builds brdfd, brdf-sim
#        and brdfctl unless BENCH_NO_BUILD=1)
# Environment: COST_STEPS (grid steps, "2,2,2": 45 × 45 × 90 cells), COST_REPS (5),
# COST_METHOD (octant), COST_FILL (chain), COST_DB=FILE and COST_SESSION=ID (time that session
# instead of recording the demo plan: e.g. `bench_storage create --db FILE --readings 50000
# --bands 401 --budgets`), BENCH_KEEP=1 keeps the work directory,
# COST_PERF=FILE records brdfd with `perf record -g` into FILE while the timed calls run.
# Prints brdfd's peak memory (VmHWM) at the end.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac

# shellcheck source=bench/daemon/lib.sh
source "$root/bench/daemon/lib.sh"
bench_rig_programs grid_cost "$build"
bench_workdir_and_cleanup /tmp/brdfd-grid-cost.XXXXXX
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'

echo "grid export's uncertainty: cost — $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) CPUs"
echo "load at start: $(cut -d' ' -f1-3 /proc/loadavg)"
if [[ -n "${COST_DB:-}" ]]; then
  # A session made elsewhere (bench_storage create --budgets), copied: brdfd opens the copy.
  cp "$COST_DB" "$work/brdfd.db"
  start_rig_on_sim "$work" 8 warn
  session="${COST_SESSION:?COST_SESSION: the session id in COST_DB}"
  echo "session $session of $COST_DB"
else
  start_rig_on_sim "$work" 8 warn
  record_session_on_sim "$root/examples/plans/demo.json" "$work/watch.out"
  echo "session $session recorded (demo plan)"
fi

steps="${COST_STEPS:-2,2,2}"
cpu_ticks() {  # brdfd's user + system time so far, clock ticks
  awk '{print $14 + $15}' "/proc/$brdfd_pid/stat"
}
export_once() {  # $1: "" or --uncertainty; prints "wall_seconds cpu_seconds"
  local t0 t1 c0 c1
  rm -f "$work"/g.*
  c0="$(cpu_ticks)"
  t0="$(date +%s.%N)"
  "$ctl" export "$session" grid \
    -o "$work/g.npy" --steps "$steps" --float32 --method "${COST_METHOD:-octant}" \
    --fill "${COST_FILL:-chain}" ${1:+"$1"} >/dev/null 2>"$work/export.err" || {
    cat "$work/export.err" >&2
    exit 1
  }
  t1="$(date +%s.%N)"
  c1="$(cpu_ticks)"
  echo "$(echo "$t1 - $t0" | bc) $(echo "scale=3; ($c1 - $c0) / $(getconf CLK_TCK)" | bc)"
}
perf_pid=""
if [[ -n "${COST_PERF:-}" ]]; then
  perf record -g -q -o "$COST_PERF" -p "$brdfd_pid" 2>/dev/null &
  perf_pid=$!
  sleep 1
fi
plain=()
with=()
for ((r = 0; r < ${COST_REPS:-5}; r++)); do
  if ((r % 2 == 0)); then
    plain+=("$(export_once "")")
    with+=("$(export_once --uncertainty)")
  else
    with+=("$(export_once --uncertainty)")
    plain+=("$(export_once "")")
  fi
done
if [[ -n "$perf_pid" ]]; then
  kill -INT "$perf_pid" 2>/dev/null || true
  wait "$perf_pid" 2>/dev/null || true
fi
find "$work" -maxdepth 1 -name 'g.*' -printf '  %s bytes  %p\n' | sort -k3
python3 - "${plain[*]}" "${with[*]}" <<'PY'
import statistics, sys
pairs = [[float(x) for x in arg.split()] for arg in sys.argv[1:3]]
for col, what in ((0, "wall"), (1, "brdfd's CPU")):
    plain, with_u = pairs[0][col::2], pairs[1][col::2]
    a, b = statistics.median(plain), statistics.median(with_u)
    print(f"grid export ({what}), without uncertainty: {' '.join(f'{x:.2f}' for x in plain)} s, median {a:.2f} s")
    print(f"grid export ({what}), with uncertainty:    {' '.join(f'{x:.2f}' for x in with_u)} s, median {b:.2f} s")
    print(f"ratio (medians, {what}): {b / a:.2f}")
PY
# The most brdfd held at once over the run (both kinds of export and the session's load).
echo "brdfd's peak memory (VmHWM): $(awk '/^VmHWM/ {print $2, $3}' "/proc/$brdfd_pid/status")"
echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
