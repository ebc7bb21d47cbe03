#!/usr/bin/env bash
# A soak (issue 40): brdfd records examples/plans/paper-grid.json on brdf-sim at time scale 32,
# session after session, while analysts come and go: watchers, readings streams following the
# session, Interpolate calls, exports read to the end, and clients that never read (an export and
# a readings stream piped into a process that does not read: the client stops reading once the
# pipe is full, so brdfd's writes wait under flow control). Every 10 s it samples brdfd's resident
# memory, threads and open file descriptors; at the end it fits a line to each over the last half
# of the run (after the warm-up) and checks that none grows: the fitted change over the last half
# at most SOAK_MAX_RSS_MB (24 MB), SOAK_MAX_THREADS (8) and SOAK_MAX_FDS (8). The index cache is
# held to SOAK_INDEX_SESSIONS sessions ([index] max_sessions, default 2 here, 8 in brdfd): a cached
# paper-grid session (2,112 readings of 101 bands with their uncertainty budgets and the octant
# BRDF index) holds ~25 MB, and an hour records only ~8 sessions, so with brdfd's 8 the cache
# would still be filling at the end (+30 MB a session: RSS 29 → 305 MB, "+86 MB" over the last
# half) and the check would measure the cache, not a leak; with 2 it is full after the first
# quarter and the last half is steady state. The exports' kept interpolants likewise, to
# SOAK_EXPORT_ENTRIES ([export] max_entries, default 1 here, 4 in brdfd): a kept paper-grid
# interpolant (the session copy, its index, Delaunay fallback and fitted model) holds ~45 MB and
# the analysts export the current session over and over, so brdfd's 4 keep one more each session
# for the first four (+57 MB over the last half of an hour with 4); with 1 the entry of the
# session before is dropped when the next is exported (50 minutes, 5 sessions, load average 6–20:
# floor fit −0.2 MB, RSS 29 MB first, 302 max, 187 last). RSS is fitted through each minute's
# smallest sample (the floor between the analysts' calls in flight: a leak raises it, a burst of exports
# does not); the fit through every sample is printed beside it. Then, from the database, that every reading
# step done holds exactly one reading and no reading is stored twice.
#
# Usage: bench/daemon/soak.sh [BUILD_DIR] (default: build-bench; builds what it needs unless
# BENCH_NO_BUILD=1). SOAK_DURATION_S (default 3600), SOAK_SAMPLE_S (10), SOAK_TIME_SCALE (32),
# SOAK_INDEX_SESSIONS (2), SOAK_EXPORT_ENTRIES (1), BENCH_KEEP=1 keeps the work directory
# (samples in soak.samples: seconds, RSS kB, threads, fds).
# Prints one line of key=value figures; exits 1 when a check fails.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-${BRDF_BENCH_BUILD:-$root/build-bench}}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
duration="${SOAK_DURATION_S:-3600}"
period="${SOAK_SAMPLE_S:-10}"
scale="${SOAK_TIME_SCALE:-32}"
if [[ "${BENCH_NO_BUILD:-0}" != 1 ]]; then
  if [[ ! -f "$build/build.ninja" && ! -f "$build/Makefile" ]]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  cmake --build "$build" -j2 --target brdfd brdf-sim brdfctl >&2
fi
brdfd="$build/daemon/brdfd"
sim="$build/tools/brdf-sim/brdf-sim"
ctl="$build/tools/brdfctl/brdfctl"

# shellcheck source=bench/daemon/lib.sh
source "$here/lib.sh"
bench_workdir_and_cleanup /tmp/brdfd-soak.XXXXXX
load_start="$(cut -d' ' -f1-3 /proc/loadavg | tr ' ' /)"

# The caches full early (see above): the last half then measures leaks, not the caches filling.
config_extra="$(printf '[index]\nmax_sessions = %s\n[export]\nmax_entries = %s\n' \
  "${SOAK_INDEX_SESSIONS:-2}" "${SOAK_EXPORT_ENTRIES:-1}")"
start_rig_on_sim "$work" "$scale" warn
deadline=$((SECONDS + duration))
running() { ((SECONDS < deadline)); }

# The operator: paper-grid sessions back to back; the current one's id in $work/current.
on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "$modbus")"
operator() {
  while running; do
    local session
    session="$("$ctl" submit "$root/examples/plans/paper-grid.json" --start --quiet)"
    echo "$session" >"$work/current"
    echo "$session" >>"$work/sessions"
    timeout $((deadline - SECONDS + 1)) "$ctl" watch "$session" --auto-confirm \
      --on-prompt "$on_prompt" --exit-on-pause >>"$work/watch.out" 2>&1 </dev/null || true
  done
  "$ctl" abort "$(cat "$work/current")" --reason "soak over" >/dev/null 2>&1 || true
}

# One analyst's habit, over and over until the end: $1 the kind, with the analyst token.
analyst() {
  local kind="$1" session
  while running; do
    session="$(cat "$work/current" 2>/dev/null || true)"
    if [[ -z "$session" ]]; then sleep 1; continue; fi
    case "$kind" in
      watch) timeout $((5 + RANDOM % 40)) "$ctl" --token "$analyst_token" watch "$session" ;;
      readings) timeout $((5 + RANDOM % 40)) "$ctl" --token "$analyst_token" readings "$session" \
        --follow ;;
      interpolate)
        for ((i = 0; i < 50; i++)); do
          "$ctl" --token "$analyst_token" interpolate "$session" --theta-i $((10 + RANDOM % 60)) \
            --theta-o $((10 + RANDOM % 60)) --phi $((RANDOM % 180)) || true
          sleep 0.1
        done ;;
      export)
        "$ctl" --token "$analyst_token" export "$session" grid --steps 5 -o "$work/grid.npy" \
          --no-progress
        "$ctl" --token "$analyst_token" export "$session" csv -o "$work/readings.csv" \
          --no-progress ;;
      # Never read: the pipe fills, the client stops reading, brdfd's writes wait.
      unread) timeout $((10 + RANDOM % 30)) bash -c "$(printf '%q' "$ctl") --token \
        $(printf '%q' "$analyst_token") readings $session --follow --spectra | sleep 3600" ;
        timeout $((10 + RANDOM % 30)) bash -c "$(printf '%q' "$ctl") --token \
        $(printf '%q' "$analyst_token") export $session csv --quantity radiance -o - \
        --no-progress | sleep 3600" ;;
    esac >/dev/null 2>&1 || true
    sleep $((RANDOM % 3))
  done
}

echo "== soak: paper-grid at time scale $scale for $duration s, analysts coming and going" >&2
operator &
pids+=("$!")
for kind in watch watch readings readings interpolate interpolate export unread unread; do
  analyst "$kind" &
  pids+=("$!")
done
sample_rss "$brdfd_pid" "$work/soak.samples" "$period" &
pids+=("$!")
while running; do sleep 1; done
sleep 3  # the clients' last calls end; then brdfd stops and the database is checked
for p in "${pids[@]:2}"; do stop_pid "$p"; done
stop_pid "$brdfd_pid"

# Every reading step done holds one reading; no step holds two.
db="$work/brdfd.db"
check="$(sqlite3 -readonly -separator ' ' "$db" "
  SELECT
    (SELECT count(*) FROM readings),
    (SELECT count(*) FROM steps WHERE kind IN ('reference', 'dark', 'sample') AND state = 'done'),
    (SELECT count(*) FROM (SELECT session_id, step_index FROM readings
                           GROUP BY session_id, step_index HAVING count(*) > 1)),
    (SELECT count(*) FROM steps s WHERE s.kind IN ('reference', 'dark', 'sample')
       AND s.state = 'done' AND NOT EXISTS (SELECT 1 FROM readings r
         WHERE r.session_id = s.session_id AND r.step_index = s.step_index)),
    (SELECT count(*) FROM sessions)")"
read -r readings done_steps doubled missing sessions <<<"$check"

# Least-squares line over the last half of the samples: its change across that half.
python3 - "$work/soak.samples" "$duration" "${SOAK_MAX_RSS_MB:-24}" "${SOAK_MAX_THREADS:-8}" \
  "${SOAK_MAX_FDS:-8}" "$readings" "$done_steps" "$doubled" "$missing" "$sessions" \
  "$load_start" "$(cut -d' ' -f1-3 /proc/loadavg | tr ' ' /)" <<'EOF'
import sys
path, duration = sys.argv[1], float(sys.argv[2])
max_rss_mb, max_threads, max_fds = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
readings, done_steps, doubled, missing, sessions = map(int, sys.argv[6:11])
rows = [list(map(float, line.split())) for line in open(path) if len(line.split()) == 4]
half = [r for r in rows if r[0] >= rows[-1][0] / 2] if rows else []
def change(col):
    xs = [r[0] for r in half]; ys = [r[col] for r in half]
    n = len(xs)
    if n < 3: return 0.0
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx else 0.0
    return slope * (xs[-1] - xs[0])
# The floor: each minute's smallest RSS (what brdfd holds between the analysts' calls in flight);
# a leak raises it, a burst of exports does not.
floor = {}
for r in half:
    minute = int(r[0] // 60)
    floor[minute] = min(floor.get(minute, r), r, key=lambda row: row[1])
floor_rows = sorted(floor.values())
def floor_change():
    xs = [r[0] for r in floor_rows]; ys = [r[1] for r in floor_rows]
    n = len(xs)
    if n < 2: return change(1)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return (sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx else 0.0) * (xs[-1] - xs[0])
rss, threads, fds = floor_change() / 1024, change(2), change(3)
rss_all = change(1) / 1024
ok = (len(half) >= 3 and rss <= max_rss_mb and threads <= max_threads and fds <= max_fds
      and doubled == 0 and missing == 0 and readings == done_steps)
last = rows[-1] if rows else [0, 0, 0, 0]
print(f"soak_s={duration:.0f} samples={len(rows)} sessions={sessions} readings={readings} "
      f"reading_steps_done={done_steps} doubled={doubled} missing={missing} "
      f"rss_first_mb={rows[0][1] / 1024 if rows else 0:.1f} rss_max_mb="
      f"{max(r[1] for r in rows) / 1024 if rows else 0:.1f} rss_last_mb={last[1] / 1024:.1f} "
      f"threads_last={last[2]:.0f} fds_last={last[3]:.0f} last_half_fit_rss_floor_mb={rss:+.1f} "
      f"(≤ {max_rss_mb:g}) last_half_fit_rss_all_samples_mb={rss_all:+.1f} last_half_fit_threads={threads:+.1f} (≤ {max_threads:g}) "
      f"last_half_fit_fds={fds:+.1f} (≤ {max_fds:g}) loadavg_start={sys.argv[11]} "
      f"loadavg_end={sys.argv[12]} {'ok' if ok else 'FAILED'}")
sys.exit(0 if ok else 1)
EOF
