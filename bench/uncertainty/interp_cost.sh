#!/usr/bin/env bash
# What asking for uncertainties costs Interpolate and InterpolateBatch (issue 37, deliverable 6:
# at most 1.5× the time without): records examples/plans/demo.json on brdf-sim through brdfd (87
# sample readings, each with its stored budget), then bench_interp_uncertainty times, in the same
# run, Interpolate (sequential calls) and InterpolateBatch (one call) at random directions with
# and without include_uncertainty, alternating which goes first, and prints medians and ratios
# (the batch's also split into the daemon's and the client's CPU time).
#
# Usage: bench/uncertainty/interp_cost.sh [BUILD_DIR]   (default ./build; builds brdfd, brdf-sim,
#        brdfctl and bench_interp_uncertainty unless BENCH_NO_BUILD=1)
# Environment: COST_CALLS (Interpolate calls per timing, 2000), COST_DIRECTIONS (batch size,
# 20000), COST_REPS (5), COST_METHOD (octant), COST_SHARED=1 (the batch's answers also carry the
# shared part: include_uncertainty_shared), COST_DB=FILE and COST_SESSION=ID (that session
# instead of recording the demo plan), COST_DUMP=FILE (one batch's answers with every part, to
# compare builds), COST_BENCH (another bench_interp_uncertainty), BENCH_KEEP=1 keeps the work directory,
# COST_PERF=FILE records brdfd with `perf record -g` into FILE while the timed calls run.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac

# shellcheck source=bench/daemon/lib.sh
source "$root/bench/daemon/lib.sh"
bench_rig_programs interp_cost "$build" bench_interp_uncertainty
bench="${COST_BENCH:-$build/bench/uncertainty/bench_interp_uncertainty}"
bench_workdir_and_cleanup /tmp/brdfd-interp-cost.XXXXXX
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'

echo "interpolated values' uncertainty: cost — $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) CPUs"
echo "load at start: $(cut -d' ' -f1-3 /proc/loadavg)"
if [[ -n "${COST_DB:-}" ]]; then
  # A session recorded or made before (BENCH_KEEP=1 keeps one), copied: brdfd opens the copy.
  cp "$COST_DB" "$work/brdfd.db"
  start_rig_on_sim "$work" 8 warn
  session="${COST_SESSION:?COST_SESSION: the session id in COST_DB}"
else
  start_rig_on_sim "$work" 8 warn
  record_session_on_sim "$root/examples/plans/demo.json" "$work/watch.out"
fi
budgets="$(sqlite3 -readonly "$work/brdfd.db" \
  "SELECT count(*) FROM reading_uncertainty u JOIN readings r ON r.id = u.reading_id
   WHERE r.session_id = $session")"
echo "session $session recorded (demo plan); sample readings with a budget: $budgets"

perf_pid=""
if [[ -n "${COST_PERF:-}" ]]; then
  perf record -g -q -o "$COST_PERF" -p "$brdfd_pid" 2>/dev/null &
  perf_pid=$!
  sleep 1
fi
"$bench" --address "$BRDF_ADDRESS" --token "$analyst_token" --session "$session" \
  --calls "${COST_CALLS:-2000}" --directions "${COST_DIRECTIONS:-20000}" \
  --reps "${COST_REPS:-5}" --method "${COST_METHOD:-octant}" --daemon-pid "$brdfd_pid" \
  ${COST_SHARED:+--shared} ${COST_DUMP:+--dump "$COST_DUMP"}
if [[ -n "$perf_pid" ]]; then
  kill -INT "$perf_pid" 2>/dev/null || true
  wait "$perf_pid" 2>/dev/null || true
fi
echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
