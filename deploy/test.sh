#!/usr/bin/env bash
# The README's test command: installs what is missing, configures, builds and runs every test with
# ctest. Exits non-zero on any failure.
# Environment: BUILD_DIR (default build), JOBS (default: number of cores), CTEST_ARGS (extra args).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
"$root/deploy/install-deps.sh"

build="${BUILD_DIR:-$root/build}"
jobs="${JOBS:-$(nproc)}"
echo "test: configuring in $build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBRDF_WERROR=ON ${CMAKE_ARGS:-}
echo "test: building with $jobs jobs"
cmake --build "$build" -j "$jobs"
echo "test: running tests"
ctest --test-dir "$build" --output-on-failure -j "$jobs" ${CTEST_ARGS:-}
