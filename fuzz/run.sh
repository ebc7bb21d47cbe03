#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang-14, ASan + UBSan, coverage-instrumented libraries) in
# build-fuzz/ and runs each for a while from its checked-in seed corpus.
#
#   fuzz/run.sh [--smoke] [seconds-per-target] [target...]
#
#   seconds-per-target  default 60 (--smoke: 8)
#   target              pr650_reply pr650_framing stage_codec stage_rtu plan_json config interp_csv
#                       stage_profile material
#                       (default: all)
#   --smoke             the CI pass: fresh scratch corpora, 8 s per target
#   --no-build          run what build-fuzz/ already holds
#
# The checked-in seeds (fuzz/corpus/<target>/) are copied into a scratch corpus
# (build-fuzz/fuzz-corpus/<target>/, kept between runs so later runs start from what earlier ones
# found; --smoke uses a fresh one) and never written to. Prints the executions per target and any
# crash, leak, timeout or out-of-memory input, and exits 1 if there was one.
# Environment: BUILD_DIR (default build-fuzz), JOBS (build jobs, default 2), CC/CXX (default
# clang-14/clang++-14), FUZZ_ARGS (extra libFuzzer flags).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build-fuzz}"
jobs="${JOBS:-2}"
all_targets=(pr650_reply pr650_framing stage_codec stage_rtu plan_json config interp_csv
  stage_profile material)

smoke=0
do_build=1
seconds=""
targets=()
for arg in "$@"; do
  case "$arg" in
    --smoke) smoke=1 ;;
    --no-build) do_build=0 ;;
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    ''|*[!0-9]*)
      if [[ " ${all_targets[*]} " != *" $arg "* ]]; then
        echo "fuzz/run.sh: unknown target '$arg' (known: ${all_targets[*]})" >&2
        exit 2
      fi
      targets+=("$arg") ;;
    *) seconds="$arg" ;;
  esac
done
[[ ${#targets[@]} -eq 0 ]] && targets=("${all_targets[@]}")
if [[ -z "$seconds" ]]; then
  if [[ $smoke -eq 1 ]]; then seconds=8; else seconds=60; fi
fi

export CC="${CC:-clang-14}" CXX="${CXX:-clang++-14}"
for tool in "$CC" "$CXX"; do
  command -v "$tool" >/dev/null || { echo "fuzz/run.sh: $tool not found (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 2; }
done

if [[ $do_build -eq 1 ]]; then
  echo "fuzz: configuring $build ($CXX, ASan+UBSan, libFuzzer)"
  # -O1 -g without NDEBUG: assertions in the code under test stay on while fuzzing.
  mkdir -p "$build"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
    -DBRDF_FUZZ=ON -DBRDF_SANITIZE=address,undefined -DBRDF_BUILD_BENCH=OFF >"$build/configure.log" 2>&1 ||
    { cat "$build/configure.log" >&2; echo "fuzz: configure failed" >&2; exit 2; }
  build_targets=()
  for t in "${targets[@]}"; do build_targets+=("${t}_fuzzer"); done
  echo "fuzz: building ${build_targets[*]} (-j$jobs)"
  cmake --build "$build" -j "$jobs" --target "${build_targets[@]}"
fi

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"

failed=()
summary=()
total_execs=0
for t in "${targets[@]}"; do
  exe="$build/fuzz/${t}_fuzzer"
  if [[ ! -x "$exe" ]]; then
    echo "fuzz: $exe is missing (was it skipped at configure time? see $build/configure.log)" >&2
    failed+=("$t(missing)")
    continue
  fi
  if [[ $smoke -eq 1 ]]; then
    work="$build/fuzz-smoke/$t"
    rm -rf "$work"
  else
    work="$build/fuzz-corpus/$t"
  fi
  mkdir -p "$work/corpus" "$work/artifacts"
  rm -f "$work/artifacts/"*
  cp -n "$root/fuzz/corpus/$t/"* "$work/corpus/" 2>/dev/null || true
  dict=()
  [[ -f "$root/fuzz/dict/$t.dict" ]] && dict=("-dict=$root/fuzz/dict/$t.dict")
  echo "fuzz: $t for ${seconds}s ($(ls "$work/corpus" | wc -l) inputs in $work/corpus)"
  set +e
  # shellcheck disable=SC2086
  "$exe" -max_total_time="$seconds" -timeout=25 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$work/artifacts/" "${dict[@]}" ${FUZZ_ARGS:-} \
    "$work/corpus" >"$work/log.txt" 2>&1
  rc=$?
  set -e
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/log.txt" | tail -1 | grep -o '[0-9]*$' || true)
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$work/log.txt" | tail -1 | grep -o '[0-9]*$' || true)
  if [[ -z "$execs" ]]; then
    # A crash ends the run before the final stats; the last status line has the count.
    execs=$(grep -oE '^#[0-9]+' "$work/log.txt" | tail -1 | tr -d '#' || true)
  fi
  total_execs=$((total_execs + ${execs:-0}))
  crashes=$(find "$work/artifacts" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | sort)
  slow=$(find "$work/artifacts" -type f -name 'slow-unit-*' | wc -l)
  if [[ $rc -ne 0 || -n "$crashes" ]]; then
    result="FAILED (exit $rc)"
    failed+=("$t")
  else
    result="ok"
  fi
  summary+=("$(printf '%-14s %12s execs %8s exec/s  corpus %5s  slow %3s  %s' "$t" "${execs:-?}" "${rate:-?}" "$(ls "$work/corpus" | wc -l)" "$slow" "$result")")
  if [[ -n "$crashes" || $rc -ne 0 ]]; then
    echo "fuzz: $t FAILED; log: $work/log.txt"
    grep -m1 -A30 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error|fuzz invariant failed' "$work/log.txt" || tail -30 "$work/log.txt"
    for f in $crashes; do
      echo "  input: $f ($(stat -c %s "$f") bytes)"
      echo "  reproduce: $exe $f"
    done
  fi
done

echo
echo "fuzz: summary (${seconds}s per target)"
printf '  %s\n' "${summary[@]}"
echo "  total: $total_execs executions"
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "fuzz: FAILED: ${failed[*]}"
  exit 1
fi
echo "fuzz: no crashes"
