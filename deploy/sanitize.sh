#!/usr/bin/env bash
# Sanitizer builds of the test suite, with GCC (Debian's gRPC, protobuf and friends are used
# as installed: uninstrumented, which ASan and UBSan do not mind; see tsan.supp for TSan).
#
#   deploy/sanitize.sh [address|thread] [extra ctest args...]
#
#   address (default)  build-asan/: -DBRDF_SANITIZE=address,undefined, the whole tree, all of ctest.
#   thread             build-tsan/: -DBRDF_SANITIZE=thread, the executor's suite (ctest -L
#                      engine). The server suites (-L daemon) need gRPC and Abseil built with
#                      TSan: with Debian's uninstrumented ones they report races inside libgrpc
#                      (see deploy/tsan.supp); try them with `deploy/sanitize.sh thread -L daemon`
#                      and BUILD_TARGETS="daemon_tests brdfd brdf-sim".
#
# Every sanitizer report goes to a file under <build>/sanitizer-logs/ (log_path), so an error in
# a child process (brdfd or brdf-sim started by a test) is caught even when the test passes. The
# script prints the failed tests and every report, and exits 1 if there was either.
# Environment: JOBS (default 2), CTEST_ARGS (extra ctest args), BUILD_TARGETS (override what is
# built; default: everything for address, the engine test executable for thread).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode="${1:-address}"
[[ $# -gt 0 ]] && shift
jobs="${JOBS:-2}"

case "$mode" in
  address)
    build="${BUILD_DIR:-$root/build-asan}"
    sanitize="address,undefined"
    labels=()
    default_targets=(all)
    ;;
  thread)
    build="${BUILD_DIR:-$root/build-tsan}"
    sanitize="thread"
    labels=(-L engine)
    default_targets=(engine_tests)
    ;;
  *)
    echo "usage: deploy/sanitize.sh [address|thread] [extra ctest args...]" >&2
    exit 2
    ;;
esac

logs="$build/sanitizer-logs"
echo "sanitize: configuring $build (GCC, -fsanitize=$sanitize)"
mkdir -p "$build"
# -g1 (line tables, no local variables) is all the reports' file:line stacks need, and builds about
# a fifth faster than -g on these gRPC- and gtest-heavy files.
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DBRDF_SANITIZE="$sanitize" -DBRDF_BUILD_BENCH=OFF -DBRDF_WERROR=OFF >"$build/configure.log" 2>&1 ||
  { cat "$build/configure.log" >&2; echo "sanitize: configure failed" >&2; exit 2; }

if [[ -n "${BUILD_TARGETS:-}" ]]; then
  read -r -a targets <<<"$BUILD_TARGETS"
else
  targets=()
  known="$(cmake --build "$build" --target help 2>/dev/null || true)"
  for t in "${default_targets[@]}"; do
    if [[ "$t" == all ]] || grep -q "^$t:" <<<"$known"; then
      targets+=("$t")
    else
      echo "sanitize: no target $t yet, skipped"
    fi
  done
fi
if [[ ${#targets[@]} -eq 0 ]]; then
  echo "sanitize: nothing to build for $mode"
  exit 0
fi
echo "sanitize: building ${targets[*]} (-j$jobs)"
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

rm -rf "$logs"
mkdir -p "$logs"
# -O1 without NDEBUG keeps assertions; UBSan stops at the first error (GCC's checks otherwise
# print and continue, and the test would pass).
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$logs/ubsan"
export ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:log_path=$logs/asan"
export LSAN_OPTIONS="print_suppressions=0"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:history_size=4:suppressions=$root/deploy/tsan.supp:log_path=$logs/tsan"

echo "sanitize: running ctest ${labels[*]:-} in $build"
set +e
ctest --test-dir "$build" --output-on-failure -j "$jobs" "${labels[@]}" ${CTEST_ARGS:-} "$@" \
  2>&1 | tee "$build/ctest.log"
ctest_rc=${PIPESTATUS[0]}
set -e

reports=$(find "$logs" -type f | sort)
echo
echo "sanitize: $mode summary"
grep -E '^[0-9]+% tests passed|Total Test time' "$build/ctest.log" || true
grep -E '^\s+[0-9]+ - .* \((Failed|Timeout|SEGFAULT|Subprocess aborted|Exception|Not Run)\)' "$build/ctest.log" || true
if [[ -n "$reports" ]]; then
  echo "sanitize: $(wc -l <<<"$reports") sanitizer report(s):"
  for r in $reports; do
    echo "---- $r"
    grep -m1 -E 'ERROR: |WARNING: ThreadSanitizer|runtime error' "$r" || head -3 "$r"
    grep -m6 -E '^\s+#[0-9]+ ' "$r" || true
  done
fi
if [[ $ctest_rc -ne 0 || -n "$reports" ]]; then
  echo "sanitize: FAILED (ctest exit $ctest_rc; reports in $logs)"
  exit 1
fi
echo "sanitize: clean"
