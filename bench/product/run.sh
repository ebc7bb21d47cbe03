#!/usr/bin/env bash
# The product operations end to end (issue 19, item 5), each beside scipy doing the same job from
# the same data, interleaved repetitions, medians:
#   1. `brdfctl export 1 grid --steps 1,1,2` of a completed 50,000-reading session held by a real
#      brdfd (90 × 90 × 90 cell centres × 101 bands, a 589 MB .npy streamed to the client's disk;
#      × 401 bands 2.4 GB), beside dd copying the same bytes to the same disk (issue 41's goals:
#      at least 5× scipy end to end, within 2× of dd),
#      octant and --method delaunay, against scipy's LinearNDInterpolator over the session's
#      sample readings (`brdfctl export 1 csv`, BRDF) on the same cells, written to a .npy;
#   2. InterpolateBatch of 100,000 random directions (θi, θo ∈ [0, 90), φ ∈ [0, 180)) over gRPC
#      (bench_interpolate_batch: one request, every chunk read), octant and delaunay, against
#      LinearNDInterpolator at the same directions; our Delaunay answers are checked against
#      scipy's (largest difference where both answer).
# Both sides read their data (brdfd: the SQLite session; scipy: the readings CSV) within the timed
# run. The session is written by bench_storage (random directions, as bench/daemon's memory figure).
#
# Usage: bench/product/run.sh [BUILD_DIR]   (default: $BRDF_BENCH_BUILD, then build-bench)
#   Builds what it needs (-j2) unless BENCH_NO_BUILD=1. Environment: BENCH_BANDS ("101 401": a
#   whole run per band count, one after the other), BENCH_REPS (3),
#   BENCH_BRDFD (another brdfd binary, e.g. an older build, for a before/after), BENCH_KEEP=1.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-${BRDF_BENCH_BUILD:-$root/build-bench}}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
reps="${BENCH_REPS:-3}"
# Band counts: each one is a whole run of its own (a session of that grid, 380–780 nm), one after
# the other; the build is made once.
bands="${BENCH_BANDS:-101 401}"
if [[ "$bands" == *" "* ]]; then
  no_build="${BENCH_NO_BUILD:-0}"
  for b in $bands; do
    BENCH_BANDS="$b" BENCH_NO_BUILD="$no_build" "$0" "$@" || exit $?
    no_build=1
  done
  exit 0
fi
# Debian's python3 has numpy and scipy; a pyenv shim earlier on PATH may not (as bench/run.sh).
py="${PYTHON:-}"
if [[ -z "$py" ]]; then
  for candidate in /usr/bin/python3 python3; do
    if "$candidate" -c "import numpy, scipy" 2>/dev/null; then py="$candidate"; break; fi
  done
fi
[[ -n "$py" ]] || { echo "bench/product: no python3 with numpy and scipy" >&2; exit 2; }

if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  if [[ ! -f "$build/build.ninja" && ! -f "$build/Makefile" ]]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  echo "== building the product bench (-j2)" >&2
  cmake --build "$build" -j2 --target brdfd brdfctl bench_storage bench_interpolate_batch >&2
fi
brdfd="${BENCH_BRDFD:-$build/daemon/brdfd}"
ctl="$build/tools/brdfctl/brdfctl"

work="$(mktemp -d /tmp/brdfd-product.XXXXXX)"
shm_parent=/dev/shm
[[ -d "$shm_parent" && -w "$shm_parent" ]] || shm_parent="$work"
shm="$(mktemp -d "$shm_parent/brdfd-product.XXXXXX")"
brdfd_pid=""
cleanup() {
  if [[ -n "$brdfd_pid" ]]; then kill -TERM "$brdfd_pid" 2>/dev/null || true; wait "$brdfd_pid" 2>/dev/null || true; fi
  rm -rf "$shm"
  if [[ "${BENCH_KEEP:-0}" == 1 ]]; then echo "kept: $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT

echo "brdfd product bench — $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) CPUs, brdfd $brdfd"
echo "scipy $("$py" -c 'import scipy; print(scipy.__version__)'); uptime at start: $(uptime)"

token="bench-analyst-$(od -An -N8 -tx1 /dev/urandom | tr -d ' \n')"
echo "== a completed 50,000-reading session (bench_storage create, on $shm_parent)" >&2
"$build/bench/daemon/bench_storage" create --db "$shm/s50k.db" --readings 50000 --bands "$bands" >&2
# No rig: nothing at the meter port or the Modbus address (brdfd starts without its devices).
cat >"$work/brdfd.toml" <<TOML
[server]
listen = "127.0.0.1:0"
[storage]
database = "$shm/s50k.db"
[meter]
port = "$work/no-such-meter"
[stage]
transport = "tcp"
address = "127.0.0.1:9"
[[auth.tokens]]
name = "bench-analyst"
token = "$token"
role = "analyst"
[log]
level = "warn"
TOML
"$brdfd" --config "$work/brdfd.toml" --shutdown-timeout 3 >"$work/brdfd.out" 2>"$work/brdfd.log" </dev/null &
brdfd_pid=$!
for ((i = 0; i < 200; i++)); do grep -q '^brdfd listening on' "$work/brdfd.out" && break; sleep 0.1; done
address="$(awk '/^brdfd listening on/ { print $4 }' "$work/brdfd.out")"
export BRDF_ADDRESS="$address" BRDF_TOKEN="$token"

# The same data for scipy: the session's BRDF samples as the daemon exports them.
"$ctl" --timeout 600 export 1 csv --quantity brdf -o "$work/readings.csv" --no-progress >&2
"$py" - "$work/directions.csv" <<'PY'
import sys, numpy as np
rng = np.random.default_rng(19)
q = np.column_stack([rng.uniform(0, 90, 100000), rng.uniform(0, 90, 100000), rng.uniform(0, 180, 100000)])
np.savetxt(sys.argv[1], q, delimiter=",", header="theta_i,theta_o,phi", comments="", fmt="%.17g")
PY
batch() {  # $1 method, $2 spectra file or ""
  local extra=()
  [[ -n "$2" ]] && extra=(--spectra "$2")
  "$build/bench/product/bench_interpolate_batch" --address "$address" --token "$token" --session 1 \
    --directions "$work/directions.csv" --method "$1" --reps 1 --warmup 0 "${extra[@]}"
}
# The indexes' first builds (both methods) before the timed batches.
batch octant "" >/dev/null
batch delaunay "" >/dev/null

field() { tr ' ' '\n' <<<"$1" | awk -F= -v k="$2" '$1 == k { print $2 }'; }
now() { date +%s.%N; }
declare -a g_oct g_dd g_del g_scipy g_scipy_c b_oct b_del b_scipy b_scipy_c
# scipy's total, and its compute alone (triangulation, interpolation, the .npy) without reading the CSV.
total() { "$py" -c 'import json, sys; print("%.2f" % json.loads(sys.argv[1])["total_s"])' "$1"; }
compute() { "$py" -c 'import json, sys; j = json.loads(sys.argv[1]); print("%.2f" % (j["build_s"] + j["interp_s"]))' "$1"; }
for ((r = 0; r < reps; r++)); do
  echo "== repetition $((r + 1)) of $reps" >&2
  t0=$(now); "$ctl" --timeout 600 export 1 grid --steps 1,1,2 -o "$work/grid-octant.npy" --no-progress >&2; t1=$(now)
  g_oct+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')")
  # The disk's speed for the same bytes: the file just written, copied by dd to the same directory
  # (from the page cache; neither side syncs).
  t0=$(now); dd if="$work/grid-octant.npy" of="$work/grid-dd.npy" bs=4M status=none; t1=$(now)
  g_dd+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')")
  t0=$(now); "$ctl" --timeout 600 export 1 grid --steps 1,1,2 --method delaunay -o "$work/grid-delaunay.npy" --no-progress >&2; t1=$(now)
  g_del+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')")
  s="$("$py" "$here/scipy_side.py" grid "$work/readings.csv" "$work/grid-scipy.npy" 1 1 2)"
  echo "   scipy grid: $s" >&2
  g_scipy+=("$(total "$s")"); g_scipy_c+=("$(compute "$s")")
  line="$(batch octant "")"; echo "   $line" >&2; b_oct+=("$(field "$line" wall_s)")
  line="$(batch delaunay "$work/batch-delaunay.raw")"; echo "   $line" >&2; b_del+=("$(field "$line" wall_s)")
  s="$("$py" "$here/scipy_side.py" batch "$work/readings.csv" "$work/directions.csv" "$work/batch-scipy.raw")"
  echo "   scipy batch: $s" >&2
  b_scipy+=("$(total "$s")"); b_scipy_c+=("$(compute "$s")")
  rm -f "$work"/grid-*.npy
done
check="$("$py" - "$work/batch-delaunay.raw" "$work/batch-scipy.raw" <<'PY'
import sys, numpy as np
a = np.fromfile(sys.argv[1]).reshape(100000, -1); b = np.fromfile(sys.argv[2]).reshape(100000, -1)
both = ~np.isnan(a[:, 0]) & ~np.isnan(b[:, 0])
d = np.abs(a[both] - b[both]) / np.maximum(np.abs(b[both]), 1e-300)
print(f"{both.sum()} directions both answered, {(~np.isnan(a[:, 0])).sum()} ours, {(~np.isnan(b[:, 0])).sum()} scipy's; "
      f"largest relative difference {d.max():.2e}, median {np.median(d):.2e}")
PY
)"

med() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { printf "%.2f", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f×", a / b }'; }
# The median over the repetitions of scipy's time ÷ ours in the same repetition: $1, $2 names of
# the two arrays (each repetition's pair ran back to back, under the same load).
pair_ratio() {
  local -n a="$1" b="$2"
  local i
  for i in "${!a[@]}"; do awk -v x="${a[$i]}" -v y="${b[$i]}" 'BEGIN { print x / y }'; done |
    sort -g | awk '{ v[NR] = $1 } END { printf "%.2f×", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}
echo
echo "== product operations end to end, 50,000-reading session, $bands bands (medians of $reps, interleaved)"
printf '%-62s %s\n' "figure" "value"
printf '%-62s %s\n' "grid 1°×1°×2° (729,000 cells × $bands bands), brdfctl export, octant" "$(med "${g_oct[@]}") s (all: ${g_oct[*]})"
printf '%-62s %s\n' "  dd of the same bytes to the same disk" "$(med "${g_dd[@]}") s (all: ${g_dd[*]})"
printf '%-62s %s\n' "  ours ÷ dd: octant (goal ≤ 2×)" "$(pair_ratio g_oct g_dd)"
printf '%-62s %s\n' "  the same, --method delaunay" "$(med "${g_del[@]}") s (all: ${g_del[*]})"
printf '%-62s %s\n' "  scipy LinearNDInterpolator, same samples and cells, to .npy" "$(med "${g_scipy[@]}") s (all: ${g_scipy[*]})"
printf '%-62s %s\n' "    of which triangulation + interpolation + .npy" "$(med "${g_scipy_c[@]}") s (all: ${g_scipy_c[*]})"
printf '%-62s %s\n' "  scipy ÷ ours: octant, delaunay" "$(ratio "$(med "${g_scipy[@]}")" "$(med "${g_oct[@]}")"), $(ratio "$(med "${g_scipy[@]}")" "$(med "${g_del[@]}")") (median of each repetition's: $(pair_ratio g_scipy g_oct), $(pair_ratio g_scipy g_del))"
printf '%-62s %s\n' "  scipy without reading its CSV ÷ ours: octant, delaunay" "$(ratio "$(med "${g_scipy_c[@]}")" "$(med "${g_oct[@]}")"), $(ratio "$(med "${g_scipy_c[@]}")" "$(med "${g_del[@]}")") (per repetition: $(pair_ratio g_scipy_c g_oct), $(pair_ratio g_scipy_c g_del))"
printf '%-62s %s\n' "InterpolateBatch, 100,000 directions over gRPC, octant" "$(med "${b_oct[@]}") s (all: ${b_oct[*]})"
printf '%-62s %s\n' "  the same, delaunay" "$(med "${b_del[@]}") s (all: ${b_del[*]})"
printf '%-62s %s\n' "  scipy LinearNDInterpolator, same samples and directions" "$(med "${b_scipy[@]}") s (all: ${b_scipy[*]})"
printf '%-62s %s\n' "    of which triangulation + interpolation" "$(med "${b_scipy_c[@]}") s (all: ${b_scipy_c[*]})"
printf '%-62s %s\n' "  scipy ÷ ours: octant, delaunay" "$(ratio "$(med "${b_scipy[@]}")" "$(med "${b_oct[@]}")"), $(ratio "$(med "${b_scipy[@]}")" "$(med "${b_del[@]}")") (median of each repetition's: $(pair_ratio b_scipy b_oct), $(pair_ratio b_scipy b_del))"
printf '%-62s %s\n' "  scipy without reading its CSV ÷ ours: octant, delaunay" "$(ratio "$(med "${b_scipy_c[@]}")" "$(med "${b_oct[@]}")"), $(ratio "$(med "${b_scipy_c[@]}")" "$(med "${b_del[@]}")") (per repetition: $(pair_ratio b_scipy_c b_oct), $(pair_ratio b_scipy_c b_del))"
printf '%-62s %s\n' "  our delaunay vs scipy's answers" "$check"
echo "uptime at end: $(uptime)"
