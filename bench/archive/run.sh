#!/usr/bin/env bash
# The lab archive's figures: bench_archive_lag (README "Lab archive"). Needs Debian's postgresql-15
# (deploy/install-deps.sh). Usage: bench/archive/run.sh [BUILD_DIR]  (default: build-bench)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-${BRDF_BENCH_BUILD:-$root/build-bench}}"
if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j2 --target bench_archive_lag
fi
echo "load: $(uptime)"
"$build/bench/archive/bench_archive_lag" "$@"
echo "load: $(uptime)"
