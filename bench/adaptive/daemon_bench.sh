#!/usr/bin/env bash
# Issue 38's benchmark (deliverable 5) through the real daemon (docs/adaptive.md, "The benchmark
# through the daemon"): for each material file, brdf-sim mounts it and brdfd runs on a fresh
# SQLite database; brdfctl records the paper grid and adaptive sessions at reading budgets of 10,
# 20, 30 and 50 % of the grid's readings (examples/plans/adaptive.json with the budgets changed),
# the prompts answered on the simulator (`brdfctl watch --auto-confirm --on-prompt "brdfctl
# sim-mount from-prompt …"`, as the quickstart does); then daemon_bench_error.py measures each
# session's error against `brdf-sim truth` through the daemon's InterpolateBatch (octant method).
#
# Rig time is the daemon's estimate for a real rig (brdfd's [meter] timing left at its defaults,
# a real PR-650's; time scale 1; operator prompts at 30 s each), not the simulator's wall time:
# for the grid `brdfctl validate`'s estimate of its steps, for an adaptive session the stop's rig
# time (the same timing model over the steps it stored). The simulator runs time-scaled.
#
# Usage: bench/adaptive/daemon_bench.sh [options] [BUILD_DIR]      (BUILD_DIR default ./build)
#   --materials "A B …"  names in deploy/materials/ or paths of material files
#                        (default: paint glossy gold retro-coating blue-plastic brushed-aluminium)
#   --budgets "10 20 …"  adaptive reading budgets, % of the grid's sample readings (10 20 30 50)
#   --seed N             brdf-sim's noise seed (default 1)
#   --directions N       random direction pairs for the error (default 20000; fixed seed)
#   --time-scale S       brdf-sim's --time-scale (default 1000; see docs/adaptive.md)
#   --grid-plan FILE     the reference plan (default examples/plans/paper-grid.json)
#   --adaptive-plan FILE the adaptive plan whose budget is changed (examples/plans/adaptive.json)
#   --time-share F       the adaptive sessions' rig-time budget: F × max(budget, 20) / 20 of the
#                        grid's rig time on this rig (default 0.245: at 20 % of the readings,
#                        within the goal's quarter of the grid's time with some margin; the
#                        planner costs its budget with the same timing model as the table's rig
#                        time); 0: the reading budget alone (not with --smoke)
#   --out PREFIX         write PREFIX.csv and PREFIX.txt (default ./adaptive-daemon-bench; with
#                        --smoke, in the work directory)
#   --keep DIR           keep the work (databases, plans, logs, watch output) in DIR
#   --gamma "0 90"       the anisotropic (4D) form: both plans anisotropic over these dial
#                        positions (a motorized γ), the error judged at the four angles
#                        (θi, φi, θo, φo) without mirroring φ; rows name the material NAME-4d
#   --accept-overload    keep a reading the meter reports overloaded (quality 19), flagged,
#                        instead of pausing the session: the brushed aluminium's grazing
#                        highlight saturates the simulated PR-650 at δ 146.25° (its value is
#                        then the clipped reading, an under-read the error counts)
#   --smoke              a check in well under a minute: paint, examples/plans/demo.json as the
#                        grid, a small adaptive plan (3 detector positions), budget 50 %, 1,000
#                        directions; fails unless the table has both rows, both errors finite
#                        and below 0.5 (the paint is smooth: 0.25 in both, 2026-12-06), rig
#                        times above 0 and the adaptive readings within their budget
# Two runs' work directories (--keep) make one table with
#   bench/adaptive/daemon_bench_table.py --work DIR1 --work DIR2 --out PREFIX
# Environment: BENCH_NO_BUILD=1 (do not build brdfd, brdf-sim, brdfctl, the Python stubs).
# Exit 1 when a session does not complete or a measurement fails (the message names the log).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
materials="paint glossy gold retro-coating blue-plastic brushed-aluminium"
budgets="10 20 30 50"
seed=1
directions=20000
scale=1000
grid_plan="$root/examples/plans/paper-grid.json"
adaptive_plan="$root/examples/plans/adaptive.json"
time_share=0.245
out=""
keep=""
smoke=0
accept_overload=0
gamma=""
build=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --materials) materials="$2"; shift ;;
    --budgets) budgets="$2"; shift ;;
    --seed) seed="$2"; shift ;;
    --directions) directions="$2"; shift ;;
    --time-scale) scale="$2"; shift ;;
    --grid-plan) grid_plan="$2"; shift ;;
    --adaptive-plan) adaptive_plan="$2"; shift ;;
    --time-share) time_share="$2"; shift ;;
    --out) out="$2"; shift ;;
    --keep) keep="$2"; shift ;;
    --gamma) gamma="$2"; shift ;;
    --accept-overload) accept_overload=1 ;;
    --smoke) smoke=1 ;;
    -h | --help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    -*) echo "daemon_bench: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) build="$1" ;;
  esac
  shift
done
build="${build:-$root/build}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
if [[ $smoke == 1 ]]; then
  materials=paint budgets=50 directions=1000 grid_plan="$root/examples/plans/demo.json"
  time_share=0
fi

# shellcheck source=bench/daemon/lib.sh
source "$root/bench/daemon/lib.sh"
bench_rig_programs daemon_bench "$build" brdf_python_stubs
bench_python_with_stubs "$build"
bench_workdir_kept_or_temporary "$keep" /tmp/brdfd-adaptive-bench.XXXXXX
[[ -n "$out" ]] || out="$([[ $smoke == 1 ]] && echo "$work/table" || echo "$PWD/adaptive-daemon-bench")"
config_real_meter=1  # estimates at a real PR-650's speed (brdfd's defaults)
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'
[[ $accept_overload == 0 ]] || config_extra+=$'\n"19" = "accept_and_flag"'
four_angles=()
if [[ -n "$gamma" ]]; then
  config_extra+=$'\n[stage.axes.gamma]\npresent = true'  # brdf-sim's dial is motorized (unit 3)
  four_angles=(--four-angles)
  gamma_json="[$(tr -s ' ' ',' <<<"$gamma" | sed 's/^,//; s/,$//')]"
  jq --argjson g "$gamma_json" '.anisotropic = true | .sampleRotation.gamma = $g' "$grid_plan" \
    >"$work/grid-4d.json" || fail "cannot make the anisotropic form of $grid_plan"
  grid_plan="$work/grid-4d.json"
fi
sim_seed="$seed"

say() { echo "daemon_bench: $*" >&2; }
fail() { echo "daemon_bench: $*" >&2; exit 1; }
material_file() { if [[ -f "$1" ]]; then echo "$1"; else echo "$root/deploy/materials/$1.toml"; fi; }

# The adaptive plan with its reading budget set to $1 and its rig-time budget to $3 minutes (0:
# none; other budgets dropped), written to $2.
adaptive_plan_for() {
  # shellcheck disable=SC2016  # $n, $m and $g are jq's
  local filter='.name = "adaptive, \($n) readings" | .adaptive.budget = {maxReadings: $n}
    + (if $m > 0 then {maxRigMinutes: $m} else {} end)'
  if [[ $smoke == 1 ]]; then
    filter+=' | .adaptive.delta = {start: 0, stop: 45, step: 22.5}
      | .adaptive.seed = {retroReadings: 4, readingsPerDelta: 8} | .adaptive.roundReadings = 8'
  fi
  # shellcheck disable=SC2016
  [[ -z "$gamma" ]] || filter+=' | .anisotropic = true | .adaptive.gamma = $g'
  jq --argjson n "$1" --argjson m "$3" --argjson g "${gamma_json:-[0]}" "$filter" \
    "$adaptive_plan" >"$2"
}

# Prints a progress line every 20 s from the watch output $1 (JSON lines) until killed.
progress() {
  local what="$1" file="$2" last rounds
  while sleep 20; do
    last="$(grep '"stepCompleted"' "$file" 2>/dev/null | tail -n 1 || true)"
    [[ -n "$last" ]] || continue
    rounds="$(grep -c '"adaptiveRound"' "$file" 2>/dev/null || true)"
    jq -r --arg w "$what" --arg r "$rounds" '.stepCompleted.progress |
      "daemon_bench: \($w): \(.doneSamples // 0) sample readings, step \(.doneSteps // 0)/\(.totalSteps // 0)" +
      (if $r != "0" then ", \($r) round(s) stored" else "" end)' <<<"$last" >&2 || true
  done
}

# Records plan $1 (label $2) on the running rig; sets `session` and `wall_s`. Fails naming the logs.
record() {
  local plan="$1" label="$2" watch="$work/$material_name/$2.watch.json" on_prompt ticker t0 state
  on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "$modbus")"
  session="$("$ctl" submit "$plan" --start --quiet)" ||
    fail "$material_name $label: submitting $plan failed; brdfd's log: $dir/brdfd.log"
  say "$material_name: $label (session $session) started"
  t0=$SECONDS
  progress "$material_name $label" "$watch" &
  ticker=$!
  "$ctl" --json watch "$session" --auto-confirm --on-prompt "$on_prompt" --exit-on-pause \
    >"$watch" 2>"$watch.err" </dev/null || true
  kill "$ticker" 2>/dev/null || true
  wait "$ticker" 2>/dev/null || true
  wall_s=$((SECONDS - t0))
  state="$(sqlite3 -readonly "$dir/brdfd.db" "SELECT state || ': ' || coalesce(state_reason, '')
    FROM sessions WHERE id = $session")"
  [[ "$state" == completed* ]] ||
    fail "$material_name $label (session $session) ended $state; logs: $watch.err, $dir/brdfd.log, $dir/sim.log"
  say "$material_name: $label (session $session) $state (${wall_s} s)"
}

# The session's sample readings and prompt steps, from the database.
count_of() {
  sqlite3 -readonly "$dir/brdfd.db" "SELECT
    (SELECT count(*) FROM readings WHERE session_id = $1 AND kind = 'sample'),
    (SELECT count(*) FROM steps WHERE session_id = $1 AND kind = 'prompt')" | tr '|' ' '
}

rows="$work/rows.tsv"  # material label budget_readings readings rig_s prompts wall_s session stop
: >"$rows"
: >"$work/errors.tsv"  # material label err peak retro fallback
echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git -C "$root" rev-parse --short HEAD)," \
  "brdf-sim seed $seed, time scale $scale, $directions directions, time share $time_share${gamma:+, γ $gamma}$(
    [[ $accept_overload == 0 ]] || echo ", overloaded readings kept (flagged)")," \
  "load at the start $(cut -d' ' -f1-3 /proc/loadavg)" >"$work/meta.txt"
for m in $materials; do
  file="$(material_file "$m")"
  [[ -f "$file" ]] || fail "no material file $file (give a name in deploy/materials/ or a path)"
  material_name="$(basename "$file" .toml)${gamma:+-4d}"
  dir="$work/$material_name"
  mkdir -p "$dir"
  say "== $material_name: brdf-sim (time scale $scale, seed $seed) and brdfd on a fresh database in $dir"
  sim_extra_args=(--material "$file" --no-pacing)
  start_rig_on_sim "$dir" "$scale" warn

  grid="$("$ctl" --json validate "$grid_plan")" || fail "validate $grid_plan failed"
  grid_readings="$(jq -r '.summary.sampleReadings' <<<"$grid")"
  grid_rig_s="$(jq -r '.summary.estimatedDurationS' <<<"$grid")"
  record "$grid_plan" grid
  read -r readings prompts <<<"$(count_of "$session")"
  printf '%s\tgrid\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$material_name" "$grid_readings" "$readings" \
    "$grid_rig_s" "$prompts" "$wall_s" "$session" "every step done" >>"$rows"
  judged=(--session "grid=$session")

  for b in $budgets; do
    n=$(((grid_readings * b + 50) / 100))
    minutes="$(awk -v s="$time_share" -v b="$b" -v t="$grid_rig_s" \
      'BEGIN { printf "%.2f", s * (b > 20 ? b : 20) / 20 * t / 60 }')"
    plan="$dir/adaptive-$b.json"
    adaptive_plan_for "$n" "$plan" "$minutes"
    "$ctl" validate "$plan" >"$dir/adaptive-$b.validate" 2>&1 ||
      fail "$plan is not valid: $(cat "$dir/adaptive-$b.validate")"
    record "$plan" "adapt$b"
    stop="$(grep '"adaptiveStop"' "$work/$material_name/adapt$b.watch.json" | tail -n 1)"
    [[ -n "$stop" ]] || fail "$material_name adapt$b: no adaptive stop in $work/$material_name/adapt$b.watch.json"
    read -r readings prompts <<<"$(count_of "$session")"
    printf '%s\tadapt%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$material_name" "$b" "$n" "$readings" \
      "$(jq -r '.adaptiveStop.rigS' <<<"$stop")" "$prompts" "$wall_s" "$session" \
      "$(jq -r '.adaptiveStop.reason' <<<"$stop")" >>"$rows"
    judged+=(--session "adapt$b=$session")
  done

  say "$material_name: errors against brdf-sim truth (${directions} directions)"
  "$python" "$here/daemon_bench_error.py" --address "$BRDF_ADDRESS" --token "$operator_token" \
    --sim "$sim" --material "$file" --directions "$directions" \
    --truth-cache "$work/truth-$material_name-$directions.npz" "${judged[@]}" \
    ${four_angles[@]+"${four_angles[@]}"} \
    >"$dir/errors.jsonl" 2>"$dir/errors.log" ||
    fail "$material_name: measuring the errors failed: $(tail -n 3 "$dir/errors.log"); log $dir/errors.log"
  sed 's/^/  /' "$dir/errors.log" >&2
  jq -r --arg m "$material_name" '[$m, .label, .err, .peak, .retro, .fallback] | @tsv' \
    "$dir/errors.jsonl" >>"$work/errors.tsv"
  stop_pid "$brdfd_pid"
  stop_pid "$sim_pid"
done

# The table: the rows and errors joined, ratios to each material's grid, the goal.
table_args=()
[[ $smoke == 1 ]] && table_args+=(--smoke)
"$python" "$here/daemon_bench_table.py" --work "$work" --out "$out" ${table_args[@]+"${table_args[@]}"}
