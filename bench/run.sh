#!/usr/bin/env bash
# The interpolation benchmarks, in one run: Google Benchmark micro-benchmarks of the index and
# the blend, then our interpolation against scipy on the same data and queries (compare.py),
# the octant answers checked against the O(N) reference, and the 90×90×180 grid on 1 and 2
# threads. Prints the figures and their ratios; takes a few minutes on 2 cores. Then the daemon's
# figures (bench/daemon/run.sh) and the product operations end to end against scipy
# (bench/product/run.sh, about ten minutes more).
#
# Usage: bench/run.sh [BUILD_DIR]      (default: $BRDF_BENCH_BUILD, then build-bench)
#   Configures and builds bench_interp_micro, bench_interp_driver and brdf-interp there (-j2)
#   when needed. Environment: BENCH_REPS (default 5), BENCH_QUERIES (50000 3D queries),
#   BENCH_QUERIES_4D (20000), BENCH_4D_POINTS (4000), BENCH_KEEP=1 keeps the data folder.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/.." && pwd)"
build="${1:-${BRDF_BENCH_BUILD:-$root/build-bench}}"
reps="${BENCH_REPS:-5}"
queries="${BENCH_QUERIES:-50000}"
queries4d="${BENCH_QUERIES_4D:-20000}"
points4d="${BENCH_4D_POINTS:-4000}"

# Debian's python3 has numpy and scipy; a pyenv shim earlier on PATH may not.
py="${PYTHON:-}"
if [[ -z "$py" ]]; then
  for candidate in /usr/bin/python3 python3; do
    if "$candidate" -c "import numpy, scipy" 2>/dev/null; then py="$candidate"; break; fi
  done
fi
[[ -n "$py" ]] || { echo "bench: no python3 with numpy and scipy (apt install python3-scipy)" >&2; exit 2; }

if [[ ! -f "$build/build.ninja" && ! -f "$build/Makefile" ]]; then
  echo "== configuring $build" >&2
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
echo "== building (-j2)" >&2
cmake --build "$build" --target bench_interp_micro bench_interp_driver brdf-interp -j2 >&2

work="$(mktemp -d)"
if [[ "${BENCH_KEEP:-0}" != 1 ]]; then trap 'rm -rf "$work"' EXIT; fi

echo "brdfd interpolation bench — $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) CPUs: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
echo "build: $build ($(grep -m1 CMAKE_BUILD_TYPE: "$build/CMakeCache.txt" | cut -d= -f2)), scipy $("$py" -c 'import scipy; print(scipy.__version__)')"
echo "uptime at start: $(uptime)"
echo

interp="$build/tools/brdf-interp/brdf-interp"
"$interp" synth --grid paper -o "$work/rig.csv" 2>/dev/null
"$interp" synth --grid random 50000 --seed 12 -o "$work/random.csv" 2>/dev/null
"$interp" synth --grid random 50000 --seed 12 --bands 401 -o "$work/random401.csv" 2>/dev/null
"$interp" synth --grid random "$points4d" --seed 13 --dims 4 -o "$work/aniso4d.csv" 2>/dev/null

echo "== (a) micro-benchmarks (Google Benchmark; items/s = queries, builds or blends per second, 1 thread)"
"$build/bench/bench_interp_micro" --benchmark_min_time=0.2 --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true --benchmark_display_aggregates_only=true 2>/dev/null |
  grep -v -E '_(mean|stddev|cv) ' || true
echo

echo "== (b) our interpolation vs scipy (same files, same queries, same order, interleaved)"
status=0
"$py" "$here/compare.py" --driver "$build/bench/bench_interp_driver" --work "$work" \
  --reps "$reps" --queries "$queries" --queries-4d "$queries4d" --json "$work/results.json" || status=$?
echo
echo "uptime at end: $(uptime)"
if [[ "${BENCH_KEEP:-0}" == 1 ]]; then echo "data and results.json kept in $work"; fi
if [[ $status -ne 0 ]]; then echo "bench: MISMATCHES against the reference (see above)"; fi
echo; "$here/daemon/run.sh" "$build" || echo "bench: the daemon figures (bench/daemon/run.sh) failed; see above"
echo; BENCH_REPS=3 "$here/product/run.sh" "$build" ||
  echo "bench: the product figures (bench/product/run.sh) failed; see above"
exit $status
