#!/usr/bin/env bash
# The sample-fixed method's form of issue 38 (docs/adaptive.md, "The sample-fixed method's form")
# on brdf-sim through brdfd and brdfctl: where every pose is a prompt (the operator places lamp and
# detector by hand), is the adaptive planner's choice of poses better than a uniform set of the
# same number of prompts?
#
# For each material: brdf-sim mounts it (time scale --time-scale), brdfd runs on a fresh SQLite
# database, and brdfctl records
#   uniform   a fixed sample-fixed plan of 64 targets, θi and θo in {10, 30, 50, 70}° and the
#             relative azimuth φ in {0, 60, 120, 180}°, references by time (every 15 min);
#   adaptive  examples/plans/adaptive-sample-fixed.json with the uniform plan's prompts as its
#             prompt budget (the readings follow from it), the rest as the example has it;
# both with the meter's adaptive integration (a glossy peak overloads the example's 500 ms);
# their prompts answered by `brdfctl watch --on-prompt "brdfctl sim-mount from-prompt"`, which
# places the simulator's lamp and detector at each prompt's target. The error of each against
# `brdf-sim truth` is daemon_bench_error.py's (relative RMS of f·cosθi·cosθo at --directions random
# direction pairs with θ ≤ 75°, the octant method with the nearest reading where it has no answer:
# column fb; the specular and retro ridges). Rig time is brdfd's estimate on a real PR-650 with
# the prompts at 30 s each.
#
# Usage: bench/adaptive/sample_fixed_bench.sh [BUILD_DIR] [--materials "paint glossy"]
#          [--seed N] [--directions N] [--time-scale X] [--keep DIR]
# Builds brdfd, brdf-sim, brdfctl and the Python stubs (-j2) unless BENCH_NO_BUILD=1. Prints the
# table on stdout; progress on stderr.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
materials="paint glossy"
seed=1
directions=20000
scale=1000
keep=""
build=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --materials) materials="$2"; shift ;;
    --seed) seed="$2"; shift ;;
    --directions) directions="$2"; shift ;;
    --time-scale) scale="$2"; shift ;;
    --keep) keep="$2"; shift ;;
    -h | --help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    -*) echo "sample_fixed_bench: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) build="$1" ;;
  esac
  shift
done
build="${build:-$root/build}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
# shellcheck source=bench/daemon/lib.sh
source "$root/bench/daemon/lib.sh"
bench_rig_programs sample_fixed_bench "$build" brdf_python_stubs
bench_python_with_stubs "$build"
bench_workdir_kept_or_temporary "$keep" /tmp/brdfd-sample-fixed-bench.XXXXXX
config_real_meter=1  # estimates at a real PR-650's speed
config_extra=$'[meter.quality]\n"10" = "accept_and_flag"'
sim_seed="$seed"
say() { echo "sample_fixed_bench: $*" >&2; }
fail() { echo "sample_fixed_bench: $*" >&2; exit 1; }

# The uniform plan: 4 × 4 × 4 targets.
"$python" - "$work/uniform.json" <<'EOF'
import json, sys
targets = [{"thetaI": ti, "thetaO": to, "phi": phi}
           for ti in (10, 30, 50, 70) for to in (10, 30, 50, 70) for phi in (0, 60, 120, 180)]
plan = {"name": "sample fixed, uniform 4 x 4 x 4", "sampleFixed": {"targets": targets},
        "reference": {"perDetectorPosition": False, "everyMinutes": 15},
        "measurement": {"integrationMs": 0, "averages": 2}}
json.dump(plan, open(sys.argv[1], "w"), indent=1)
EOF

record() {
  local plan="$1" label="$2" log="$dir/$2.watch.log" state
  record_session_on_sim "$plan" "$log" || true
  state="$(sqlite3 -readonly "$dir/brdfd.db" "SELECT state || ': ' || coalesce(state_reason, '')
    FROM sessions WHERE id = $session")"
  [[ "$state" == completed* ]] || fail "$material $label (session $session) ended $state; see $log"
  say "$material: $label (session $session) $state"
}

# The sample readings and prompts of session $1.
counts() {
  sqlite3 -readonly "$dir/brdfd.db" "SELECT
    (SELECT count(*) FROM readings WHERE session_id = $1 AND kind = 'sample'),
    (SELECT count(*) FROM steps WHERE session_id = $1 AND kind = 'prompt')" | tr '|' ' '
}

echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git -C "$root" rev-parse --short HEAD), brdf-sim seed $seed," \
  "time scale $scale, $directions directions (θ ≤ 75°), load $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-10s %-9s %8s %8s %9s %8s %8s %8s %6s\n' material design readings prompts "rig time" err peak retro fb
for material in $materials; do
  file="$root/deploy/materials/$material.toml"
  [[ -f "$file" ]] || fail "no material file $file"
  dir="$work/$material"
  mkdir -p "$dir"
  sim_extra_args=(--material "$file")
  say "== $material: brdf-sim and brdfd in $dir"
  start_rig_on_sim "$dir" "$scale" warn
  uniform="$("$ctl" --json validate "$work/uniform.json")" || fail "validate uniform.json failed"
  uniform_rig_s="$(jq -r '.summary.estimatedDurationS' <<<"$uniform")"
  record "$work/uniform.json" uniform
  uniform_id="$session"
  read -r u_readings u_prompts <<<"$(counts "$uniform_id")"
  jq --argjson p "$u_prompts" '.name = "adaptive sample-fixed, \($p) prompts"
    | .adaptive.budget = {maxPrompts: $p} | .measurement.integrationMs = 0' "$root/examples/plans/adaptive-sample-fixed.json" \
    >"$dir/adaptive.json"
  record "$dir/adaptive.json" adaptive
  adaptive_id="$session"
  read -r a_readings a_prompts <<<"$(counts "$adaptive_id")"
  # The stop's reason says the rig time spent: "…, 67.3 min of rig time, …".
  a_rig_s="$(sqlite3 -readonly "$dir/brdfd.db" "SELECT state_reason FROM sessions
    WHERE id = $adaptive_id" | sed -n 's/.* \([0-9.]*\) min of rig time.*/\1/p' |
    awk '{ print $1 * 60 }')"
  [[ -n "$a_rig_s" ]] || fail "$material: the adaptive session's stop gives no rig time"
  say "$material: errors against brdf-sim truth"
  "$python" "$here/daemon_bench_error.py" --address "$BRDF_ADDRESS" --token "$operator_token" \
    --sim "$sim" --material "$file" --directions "$directions" --theta-max 75 \
    --session "uniform=$uniform_id" --session "adaptive=$adaptive_id" \
    >"$dir/errors.jsonl" 2>"$dir/errors.log" ||
    fail "$material: measuring the errors failed; log $dir/errors.log"
  for label in uniform adaptive; do
    if [[ $label == uniform ]]; then n="$u_readings" p="$u_prompts" rig="$uniform_rig_s"; else
      n="$a_readings" p="$a_prompts" rig="$a_rig_s"; fi
    jq -r --arg m "$material" --arg n "$n" --arg p "$p" --arg rig "$rig" --arg l "$label" \
      'select(.label == $l) | [$m, $l, $n, $p, (($rig | tonumber) / 60 | floor | tostring) + " min",
        (.err * 1000 | round / 1000), (.peak * 1000 | round / 1000), (.retro * 1000 | round / 1000),
        ((.fallback * 100 | round | tostring) + " %")] | @tsv' "$dir/errors.jsonl" |
      awk -F'\t' '{ printf "%-10s %-9s %8s %8s %9s %8s %8s %8s %6s\n", $1, $2, $3, $4, $5, $6, $7, $8, $9 }'
  done
  stop_pid "$brdfd_pid"
  stop_pid "$sim_pid"
done
