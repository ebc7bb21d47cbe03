#!/usr/bin/env bash
# Cross-checks brdf-interp against independent implementations:
#   - the octant method (fast and --method octant-reference) against octant_reference.py, a NumPy
#     implementation written from docs/interpolation.md: every status, the vertex
#     rows in order, weights and spectra to 1e-9, on the paper's grid (plain and with
#     --mirror-phi --reciprocity --scale), random 3D and 4D sets, and an integer lattice (ties);
#   - the Delaunay method against scipy.interpolate.LinearNDInterpolator on random 3D data in
#     general position (skipped when brdf-interp has no Delaunay method yet).
# Usage: tools/check/check_interp.sh [path/to/brdf-interp]   (default: $BRDF_INTERP, then
# build/tools/brdf-interp/brdf-interp). Needs python3 with numpy and scipy (Debian's).
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
bin="${1:-${BRDF_INTERP:-$root/build/tools/brdf-interp/brdf-interp}}"
# Debian's python3 has numpy and scipy; a pyenv shim earlier on PATH may not.
py="${PYTHON:-}"
if [[ -z "$py" ]]; then
  for candidate in /usr/bin/python3 python3; do
    if "$candidate" -c "import numpy, scipy" 2>/dev/null; then py="$candidate"; break; fi
  done
fi
[[ -n "$py" ]] || { echo "check_interp: no python3 with numpy and scipy" >&2; exit 2; }
[[ -x "$bin" ]] || { echo "check_interp: $bin is not an executable; build brdf-interp first" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
check="$py $here/check_interp.py"
failed=0
run() { "$@" || failed=1; }

# Data: the paper's grid, random 3D / 4D sets, an integer lattice.
"$bin" synth --grid paper -o "$work/paper.csv" 2>/dev/null
"$bin" synth --grid random 3000 --seed 11 -o "$work/rand3.csv" 2>/dev/null
"$bin" synth --grid random 50000 --seed 12 -o "$work/rand3_50k.csv" 2>/dev/null
"$bin" synth --grid random 4000 --seed 13 --dims 4 -o "$work/rand4.csv" 2>/dev/null
$check queries --n 4000 --lo=0,0,0 --hi=90,90,180 --seed 1 --at-samples "$work/paper.csv" \
  --at-samples-n 600 --out "$work/q_paper.csv"
$check queries --n 3000 --lo=-5,-5,-5 --hi=95,95,365 --seed 2 --at-samples "$work/rand3.csv" \
  --at-samples-n 400 --out "$work/q_rand3.csv"
$check queries --n 400 --lo=0,0,0 --hi=90,90,360 --seed 3 --out "$work/q_rand3_50k.csv"
$check queries --n 1500 --lo=0,0,0,0 --hi=90,360,90,360 --seed 4 --at-samples "$work/rand4.csv" \
  --at-samples-n 200 --out "$work/q_rand4.csv"
$check lattice --size 8 --n 2000 --seed 5 --samples "$work/lattice.csv" --queries "$work/q_lattice.csv"

octant_case() {  # label samples queries [brdf-interp options...]
  local label="$1" samples="$2" queries="$3"
  shift 3
  for method in octant octant-reference; do
    "$bin" "$samples" "$queries" --method "$method" --explain "$@" -o "$work/out.csv" 2>/dev/null
    local opts=()
    for arg in "$@"; do
      case "$arg" in
        --mirror-phi | --reciprocity) opts+=("$arg") ;;
        --scale=*) opts+=(--scale "${arg#--scale=}") ;;
      esac
    done
    run $check octant --label "$label [$method]" --samples "$samples" --output "$work/out.csv" "${opts[@]}"
  done
}

echo "== octant method vs octant_reference.py (tolerance 1e-9)"
octant_case "paper grid" "$work/paper.csv" "$work/q_paper.csv"
octant_case "paper grid, mirror+reciprocity+scale 1,1,0.5" "$work/paper.csv" "$work/q_paper.csv" \
  --mirror-phi --reciprocity --scale=1,1,0.5
octant_case "random 3D N=3000" "$work/rand3.csv" "$work/q_rand3.csv"
octant_case "random 3D N=50000" "$work/rand3_50k.csv" "$work/q_rand3_50k.csv"
octant_case "random 4D N=4000" "$work/rand4.csv" "$work/q_rand4.csv"
octant_case "integer lattice 8^3 (ties)" "$work/lattice.csv" "$work/q_lattice.csv"

echo "== delaunay method vs scipy LinearNDInterpolator (tolerance 1e-9)"
if "$bin" "$work/rand3.csv" "$work/q_rand3.csv" --method delaunay --explain -o "$work/out.csv" 2>"$work/err.txt"; then
  run $check delaunay --label "random 3D N=3000" --samples "$work/rand3.csv" --output "$work/out.csv"
  "$bin" "$work/rand4.csv" "$work/q_rand4.csv" --method delaunay --explain -o "$work/out.csv" 2>/dev/null
  run $check delaunay --label "random 4D N=4000" --samples "$work/rand4.csv" --output "$work/out.csv"
else
  echo "skipped: $(head -1 "$work/err.txt")"
fi

if [[ $failed -ne 0 ]]; then
  echo "check_interp: MISMATCHES (see above)"
  exit 1
fi
echo "check_interp: all comparisons agree"
