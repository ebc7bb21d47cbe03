#!/usr/bin/env bash
# Issue 38's benchmark (deliverable 5) through the real daemon (docs/adaptive.md, "The benchmark
# through the daemon"): for each material file, brdf-sim mounts it and brdfd runs on a fresh
# SQLite database; brdfctl records the paper grid and adaptive sessions at reading budgets of 10,
# 20, 30 and 50 % of the grid's readings (examples/plans/adaptive.json with the budget changed),
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
#   --out PREFIX         write PREFIX.csv and PREFIX.txt (default ./adaptive-daemon-bench; with
#                        --smoke, in the work directory)
#   --keep DIR           keep the work (databases, plans, logs, watch output) in DIR
#   --smoke              a check in well under a minute: paint, examples/plans/demo.json as the
#                        grid, a small adaptive plan (3 detector positions), budget 50 %, 1,000
#                        directions; fails unless the table has both rows and the grid's error
#                        is finite and below 0.5
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
out=""
keep=""
smoke=0
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
    --out) out="$2"; shift ;;
    --keep) keep="$2"; shift ;;
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
fi

if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  echo "== building brdfd, brdf-sim, brdfctl and the Python stubs (-j2)" >&2
  cmake --build "$build" -j2 --target brdfd brdf-sim brdfctl brdf_python_stubs >&2
fi
brdfd="$build/daemon/brdfd"
sim="$build/tools/brdf-sim/brdf-sim"
ctl="$build/tools/brdfctl/brdfctl"
for binary in "$brdfd" "$sim" "$ctl"; do
  [[ -x "$binary" ]] || { echo "daemon_bench: $binary is missing; build it (or unset BENCH_NO_BUILD)" >&2; exit 77; }
done
# Debian's python3 has numpy and grpcio (another python3 first on PATH, a venv, may not).
python=/usr/bin/python3
[[ -x "$python" ]] || python=python3
export BRDF_PY_STUBS="${BRDF_PY_STUBS:-$build/clients/python/stubs}"

# shellcheck source=bench/daemon/lib.sh
source "$root/bench/daemon/lib.sh"
if [[ -n "$keep" ]]; then
  mkdir -p "$keep"
  work="$(cd "$keep" && pwd)" pids=() cleanup_dirs=()
  trap bench_cleanup EXIT
  BENCH_KEEP=1
else
  bench_workdir_and_cleanup /tmp/brdfd-adaptive-bench.XXXXXX
fi
[[ -n "$out" ]] || out="$([[ $smoke == 1 ]] && echo "$work/table" || echo "$PWD/adaptive-daemon-bench")"
config_real_meter=1  # estimates at a real PR-650's speed (brdfd's defaults)
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'
sim_seed="$seed"

say() { echo "daemon_bench: $*" >&2; }
fail() { echo "daemon_bench: $*" >&2; exit 1; }
material_file() { if [[ -f "$1" ]]; then echo "$1"; else echo "$root/deploy/materials/$1.toml"; fi; }

# The adaptive plan with its reading budget set to $1 (other budgets dropped), written to $2.
adaptive_plan_for() {
  local filter='.name = "adaptive, \($n) readings" | .adaptive.budget = {maxReadings: $n}'
  if [[ $smoke == 1 ]]; then
    filter+=' | .adaptive.delta = {start: 0, stop: 45, step: 22.5}
      | .adaptive.seed = {retroReadings: 4, readingsPerDelta: 8} | .adaptive.roundReadings = 8'
  fi
  jq --argjson n "$1" "$filter" "$adaptive_plan" >"$2"
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
load_start="$(cut -d' ' -f1-3 /proc/loadavg)"
started="$(date -u '+%Y-%m-%d %H:%M UTC')"
for m in $materials; do
  file="$(material_file "$m")"
  [[ -f "$file" ]] || fail "no material file $file (give a name in deploy/materials/ or a path)"
  material_name="$(basename "$file" .toml)"
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
    plan="$dir/adaptive-$b.json"
    adaptive_plan_for "$n" "$plan"
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
    >"$dir/errors.jsonl" 2>"$dir/errors.log" ||
    fail "$material_name: measuring the errors failed: $(tail -n 3 "$dir/errors.log"); log $dir/errors.log"
  sed 's/^/  /' "$dir/errors.log" >&2
  jq -r --arg m "$material_name" '[$m, .label, .err, .peak, .retro, .fallback] | @tsv' \
    "$dir/errors.jsonl" >>"$work/errors.tsv"
  stop_pid "$brdfd_pid"
  stop_pid "$sim_pid"
done

# The table: joins the rows and the errors, ratios to the material's grid, the goal.
"$python" - "$rows" "$work/errors.tsv" "$out" "$started" "$load_start" \
  "$(cut -d' ' -f1-3 /proc/loadavg)" "$(git -C "$root" rev-parse --short HEAD)" "$seed" \
  "$scale" "$directions" "$smoke" <<'EOF'
import csv, math, sys
rows_path, err_path, out, started, load0, load1, commit, seed, scale, n, smoke = sys.argv[1:]
errs = {}
for line in open(err_path):
    m, label, err, peak, retro, fb = line.rstrip("\n").split("\t")
    errs[(m, label)] = (float(err), float(peak), float(retro), float(fb))
rows = [line.rstrip("\n").split("\t") for line in open(rows_path)]
grid = {r[0]: r for r in rows if r[1] == "grid"}
def hms(s):
    s = round(float(s)); return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"
table, verdicts = [], {}
for r in rows:
    m, label, budget, readings, rig, prompts, wall, session, stop = r
    g = grid[m]
    err, peak, retro, fb = errs[(m, label)]
    gerr = errs[(m, "grid")][0]
    e_ratio, t_ratio = err / gerr, float(rig) / float(g[4])
    r_ratio = int(readings) / int(g[3])
    goal = ""
    if label != "grid":
        a = e_ratio <= 1 and r_ratio <= 0.20 and t_ratio <= 0.25
        b = e_ratio <= 0.5
        why = [w for w, bad in (("error", e_ratio > 1), ("readings", r_ratio > 0.20),
                                ("rig time", t_ratio > 0.25)) if bad]
        goal = ("grid error at <=20% readings and <=25% time: " + ("yes" if a else "no (" + ", ".join(why) + ")")
                + "; half the grid's error: " + ("yes" if b else "no"))
        v = verdicts.setdefault(m, [False, False, math.inf])
        v[0] |= a; v[1] |= b; v[2] = min(v[2], e_ratio)
    table.append({"material": m, "plan": label, "budget_readings": budget, "readings": readings,
                  "rig_time_s": f"{float(rig):.0f}", "rig_time": hms(rig), "prompts": prompts,
                  "error": f"{err:.4f}", "peak_error": f"{peak:.4f}", "retro_error": f"{retro:.4f}",
                  "fallback_pct": f"{100 * fb:.1f}", "error_over_grid": f"{e_ratio:.3f}",
                  "readings_over_grid": f"{r_ratio:.3f}", "rig_time_over_grid": f"{t_ratio:.3f}",
                  "goal": goal, "session": session, "wall_s": wall, "stop": stop})
with open(out + ".csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(table[0]))
    w.writeheader(); w.writerows(table)
head = (f"# adaptive through brdfd on brdf-sim: {started}, commit {commit}, brdf-sim seed {seed}, "
        f"time scale {scale}, {n} directions; load {load0} -> {load1}")
lines = [head, "",
         "| material | plan | readings | rig time (÷ grid) | prompts | error (÷ grid) | peak error | retro | fb % | wall s |",
         "|---|---|---|---|---|---|---|---|---|---|"]
for t in table:
    lines.append(f"| {t['material']} | {t['plan']} | {t['readings']} ({t['readings_over_grid']}) | "
                 f"{t['rig_time']} ({t['rig_time_over_grid']}) | {t['prompts']} | {t['error']} "
                 f"({t['error_over_grid']}) | {t['peak_error']} | {t['retro_error']} | "
                 f"{t['fallback_pct']} | {t['wall_s']} |")
lines.append("")
for t in table:
    if t["goal"]:
        lines.append(f"{t['material']} {t['plan']}: {t['goal']}; stop: {t['stop']}")
lines.append("")
for m, (a, b, best) in verdicts.items():
    lines.append(f"{m}: goal (grid's error at <= 20 % readings and <= 25 % rig time) "
                 f"{'REACHED' if a else 'not reached'}; half the grid's error "
                 f"{'REACHED' if b else 'not reached'} (best error ÷ grid {best:.3f})")
text = "\n".join(lines) + "\n"
open(out + ".txt", "w").write(text)
print(text, end="")
print(f"written: {out}.csv, {out}.txt")
if smoke == "1":
    ok = (len(table) == 2 and {t["plan"] for t in table} == {"grid", "adapt50"}
          and all(math.isfinite(float(t["error"])) for t in table)
          and float(table[0]["error"]) < 0.5)
    print("smoke:", "ok" if ok else "FAILED (want a grid and an adapt50 row, finite errors, grid error < 0.5)")
    sys.exit(0 if ok else 1)
EOF
