#!/usr/bin/env bash
# How close validate's estimate is to the time a session really takes (issue 20 item 4): runs
# examples/plans/demo.json (and paper-grid.json) on brdf-sim through brdfd, and prints the
# estimate (brdfctl validate --time-scale S, rig time: the operator's prompts at 30 s each left
# out) against the session's actual time (sessions.started_at → finished_at; the prompts are
# confirmed at once by brdfctl watch --auto-confirm, mounting on the simulator), with the ratio.
#
# It also prints, per kind of reading, what brdf-sim's meter chose (integration time, from its
# debug log) and the mean time of a reading step (steps.completed_at after the step before),
# against the estimate's per-kind times ([meter] overhead_ms and adaptive_*_ms of the
# configuration written below, which are brdf-sim's: docs/pr650.md, "How long a reading takes").
#
# Usage: bench/daemon/estimate.sh [BUILD_DIR]    (default ./build; builds brdfd, brdf-sim,
#        brdfctl unless BENCH_NO_BUILD=1)
# Environment: ESTIMATE_PLANS (default "demo:8 paper-grid:32": plan name in examples/plans and
# the time scale it runs at; the paper grid's 4,710 steps take ~6.5 min at 32), BENCH_KEEP=1
# keeps the work directory (databases, logs).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
plans="${ESTIMATE_PLANS:-demo:8 paper-grid:32}"

if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  echo "== building brdfd, brdf-sim, brdfctl (-j2)" >&2
  cmake --build "$build" -j2 --target brdfd brdf-sim brdfctl >&2
fi
brdfd="$build/daemon/brdfd"
sim="$build/tools/brdf-sim/brdf-sim"
ctl="$build/tools/brdfctl/brdfctl"

# shellcheck source=bench/daemon/lib.sh
source "$here/lib.sh"
bench_workdir_and_cleanup /tmp/brdfd-estimate.XXXXXX
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'

echo "validate's estimate against brdf-sim — $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) CPUs"
echo "load at start: $(cut -d' ' -f1-3 /proc/loadavg)"
results=()
for entry in $plans; do
  name="${entry%%:*}"
  scale="${entry##*:}"
  plan="$root/examples/plans/$name.json"
  dir="$work/$name"
  mkdir -p "$dir"
  echo "== $name at time scale $scale" >&2

  start_rig_on_sim "$dir" "$scale" debug

  "$ctl" validate "$plan" --time-scale "$scale" | sed 's/^/   /' >&2
  summary="$("$ctl" --json validate "$plan" --time-scale "$scale")"
  # Rig time: the estimate without the operator's prompts (30 s each by hand).
  estimate="$(jq -r '.summary | ((.estimatedDurationS // 0) - 30 * (.operatorInterventions // 0))' \
    <<<"$summary")"

  session="$("$ctl" submit "$plan" --start --quiet)"
  on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "$modbus")"
  "$ctl" watch "$session" --auto-confirm --on-prompt "$on_prompt" --exit-on-pause \
    >"$dir/watch.out" 2>&1 </dev/null
  db="$dir/brdfd.db"
  state="$(sqlite3 -readonly "$db" "SELECT state FROM sessions WHERE id = $session")"
  actual="$(sqlite3 -readonly "$db" "SELECT finished_at - started_at FROM sessions WHERE id = $session")"
  # Per kind of reading: the mean time from the step before to this one.
  per_kind="$(sqlite3 -readonly -separator ' ' "$db" "
    SELECT s.kind, count(*), printf('%.3f', avg(s.completed_at - p.completed_at))
    FROM steps s JOIN steps p ON p.session_id = s.session_id AND p.step_index = s.step_index - 1
    WHERE s.session_id = $session AND s.kind IN ('reference', 'dark', 'sample')
    GROUP BY s.kind ORDER BY s.kind")"
  # What the simulated meter chose, by what was mounted.
  chosen="$(awk '/measure (sample|white|dark): integration/ {
      for (i = 1; i <= NF; ++i) if ($i ~ /^(sample|white|dark):$/) { k = $i; sub(":", "", k) }
      for (i = 1; i <= NF; ++i) if ($i == "integration") ms = $(i + 1)
      n[k]++; sum[k] += ms; if (!(k in lo) || ms < lo[k]) lo[k] = ms; if (ms > hi[k]) hi[k] = ms }
    END { for (k in n) printf "%s %d %.0f %d %d\n", k, n[k], sum[k] / n[k], lo[k], hi[k] }' \
    "$dir/sim.log" | sort)"
  echo "   session $session $state: estimate ${estimate} s, actual ${actual} s" >&2
  echo "   reading steps (kind, count, mean s from the step before):" >&2
  awk '{ print "     " $0 }' <<<"$per_kind" >&2
  echo "   brdf-sim's meter (mounted, measurements, mean/min/max integration ms):" >&2
  awk '{ print "     " $0 }' <<<"$chosen" >&2
  results+=("$(printf '%-12s %6s %8.1f %8.1f %6.3f  %s' "$name" "$scale" "$estimate" "$actual" \
    "$(awk -v e="$estimate" -v a="$actual" 'BEGIN { print e / a }')" "$state")")
  stop_pid "$brdfd_pid"
  stop_pid "$sim_pid"
done

echo
echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-12s %6s %8s %8s %6s  %s\n' plan scale "est. s" "act. s" ratio state
for r in "${results[@]}"; do echo "$r"; done
