#!/bin/sh
# The adaptive planner's offline study (docs/adaptive.md, "The offline study"): the planner's loop
# on brdf-sim's materials without a rig, at 10, 20, 30 and 50 % of the paper grid's readings,
# against the paper grid itself. Runs from the repository root; BUILD names the build directory.
#
#   bench/adaptive/study.sh                       paint, glossy, gold, retro-coating, seeds 1 2 3
#   MATERIALS="blue-plastic" SEEDS="1" bench/adaptive/study.sh
#   EXTRA="--candidate-step 2.5" bench/adaptive/study.sh
#   EXTRA="--plan bench/adaptive/adaptive-cheap-seed.json" bench/adaptive/study.sh   (seed.deltaEvery 4)
#   EXTRA="--refine-levels 0" bench/adaptive/study.sh          (the 5° lattice alone, as before)
#   EXTRA="--stages 20 --max-relocations -1" bench/adaptive/study.sh   (20 % only; relocations unlimited)
#   EXTRA="--detector-arm" bench/adaptive/study.sh   (a motorized detector arm, as brdf-sim's rig)
#   EXTRA="--stages 20 --detector-arm --breakdown" bench/adaptive/study.sh   (where the error is)
#   EXTRA="--stages 20 --detector-arm --grid bench/adaptive/paper-grid-fifth.json" bench/adaptive/study.sh
#                                        (against the paper grid at 464 readings: equal readings)
set -eu
BUILD=${BUILD:-build}
MATERIALS=${MATERIALS:-"paint glossy gold retro-coating"}
SEEDS=${SEEDS:-"1 2 3"}
EXTRA=${EXTRA:-}
study="$BUILD/bench/adaptive/bench_adaptive_study"
[ -x "$study" ] || { echo "study.sh: build it first: cmake --build $BUILD --target bench_adaptive_study" >&2; exit 2; }
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), load $(cut -d' ' -f1-3 /proc/loadavg), commit $(git rev-parse --short HEAD)"
for m in $MATERIALS; do
  # shellcheck disable=SC2086  # SEEDS and EXTRA are lists of words
  "$study" --material "deploy/materials/$m.toml" --seeds $SEEDS $EXTRA
done
