#!/usr/bin/env bash
# A lab in one machine: a local PostgreSQL (Debian's postgresql-15) as the lab's archive, and two
# simulated rigs (two brdf-sim, two brdfd named rig-a and rig-b) that record at the same time and
# ship everything to it, and brdf-archive, the archive's read server. Shows each rig's archive
# status (brdfctl rig), what the archive holds (psql: both rigs' sessions with their sample
# catalogue and reading counts, next to each rig's own count), then lists both rigs' sessions and
# interpolates each through ONE brdfctl pointed at brdf-archive, comparing the answer with the
# rig's own. Everything lives in ./lab-run/ (gitignored); --stop stops what it started.
#
# Usage: deploy/lab-demo.sh [--no-build]     build (unless --no-build) and run
#        deploy/lab-demo.sh --stop           stop brdf-archive, PostgreSQL, both brdfd and brdf-sim
# Environment: BUILD_DIR (default ./build), LAB_RUN_DIR (default ./lab-run), LAB_TIME_SCALE (default 8).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
run="${LAB_RUN_DIR:-$root/lab-run}"
time_scale="${LAB_TIME_SCALE:-8}"
# shellcheck source=deploy/lib.sh
source "$root/deploy/lib.sh"
resolve_build_and_run
archive_server="$build/daemon/brdf-archive"
pgbin="$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)"

say() { printf '\nlab-demo: %s\n' "$*"; }
die() {
  printf 'lab-demo: %s\n' "$*" >&2
  exit 1
}

# PostgreSQL refuses to run as root: then it runs as `nobody` in a directory nobody owns.
as_pg() {
  if [[ $(id -u) -eq 0 ]]; then setpriv --reuid=nobody --regid=nogroup --clear-groups -- "$@"; else "$@"; fi
}

stop_pid() {
  local pidfile="$1" pid i
  [[ -f "$pidfile" ]] || return 0
  pid="$(cat "$pidfile")"
  rm -f "$pidfile"
  [[ "$pid" =~ ^[0-9]+$ ]] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  for ((i = 0; i < 150; i++)); do
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL "$pid" 2>/dev/null || true
}

stop_all() {
  stop_pid "$run/archive/brdf-archive.pid"
  for r in rig-a rig-b; do stop_pid "$run/$r/brdfd.pid"; done
  for r in rig-a rig-b; do stop_pid "$run/$r/brdf-sim.pid"; done
  if [[ -f "$run/pg/data/postmaster.pid" ]]; then
    as_pg "$pgbin/pg_ctl" -D "$run/pg/data" -m fast stop >/dev/null 2>&1 || true
  fi
}

start_detached() { # pidfile out log command…
  local pidfile="$1" out="$2" log="$3"
  shift 3
  : >"$out"
  setsid bash -c 'echo $$ >"$0"; exec "$@"' "$pidfile" "$@" >"$out" 2>"$log" </dev/null &
}

wait_for_line() { # file pattern seconds
  local i
  for ((i = 0; i < $3 * 10; i++)); do
    grep -q "$2" "$1" 2>/dev/null && return 0
    sleep 0.1
  done
  die "no '$2' in $1 after $3 s"
}

free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
random_hex() { od -An -N"$1" -tx1 /dev/urandom | tr -d ' \n'; }

build_it=1
case "${1:-}" in
  --stop)
    stop_all
    echo "lab-demo: stopped (data stays in $run)"
    exit 0
    ;;
  --no-build) build_it=0 ;;
  "") ;;
  *) die "unknown argument $1 (see the top of this script)" ;;
esac

if [[ $build_it -eq 1 ]]; then
  "$root/deploy/install-deps.sh"
  pgbin="$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  cmake --build "$build" -j "$(nproc)" --target brdfd brdf-sim brdfctl brdf-archive
fi
[[ -n "$pgbin" && -x "$pgbin/initdb" ]] || die "PostgreSQL is not installed (deploy/install-deps.sh installs postgresql-15)"

mkdir -p "$run"
stop_all
rm -rf "$run/pg" "$run/rig-a" "$run/rig-b" "$run/archive"
mkdir -p "$run/pg" "$run/rig-a" "$run/rig-b" "$run/archive"
chmod 755 "$run"

# --- the archive ---------------------------------------------------------------------------------
say "starting PostgreSQL (the lab's archive) in $run/pg"
password="$(random_hex 16)"
pg_port="$(free_port)"
printf '%s\n' "$password" >"$run/pg/pwfile"
[[ $(id -u) -eq 0 ]] && chown -R nobody:nogroup "$run/pg"
chmod 700 "$run/pg"
as_pg "$pgbin/initdb" -D "$run/pg/data" -U brdf --pwfile="$run/pg/pwfile" --auth=scram-sha-256 \
  -E UTF8 --locale=C >"$run/initdb.log" 2>&1 || die "initdb failed; see $run/initdb.log"
rm -f "$run/pg/pwfile"
as_pg "$pgbin/pg_ctl" -D "$run/pg/data" -l "$run/pg/postgres.log" -w \
  -o "-k $run/pg -p $pg_port -c listen_addresses=127.0.0.1" start >/dev/null
psql_archive() { PGPASSWORD="$password" "$pgbin/psql" -X -h "$run/pg" -p "$pg_port" -U brdf -d postgres "$@"; }
echo "lab-demo: PostgreSQL on port $pg_port (socket in $run/pg)"

# --- two rigs --------------------------------------------------------------------------------------
token="$(random_hex 24)"
declare -A address modbus
seed=1
for r in rig-a rig-b; do
  d="$run/$r"
  start_detached "$d/brdf-sim.pid" "$d/brdf-sim.out" "$d/brdf-sim.log" \
    "$sim" --time-scale "$time_scale" --seed "$seed" --modbus-port 0 --pr650-link "$d/pr650" \
    --wake-window 0 --log-level warn
  seed=$((seed + 1))
  wait_for_line "$d/brdf-sim.out" '^ready' 20
  modbus[$r]="$(awk '$1 == "modbus-tcp" { print $2 }' "$d/brdf-sim.out")"
  # The credentials file: the conninfo, readable by brdfd only; never on a command line.
  (umask 077 && printf 'host=%s port=%s dbname=postgres user=brdf password=%s\n' \
    "$run/pg" "$pg_port" "$password" >"$d/archive.conninfo")
  port="$(free_port)"
  address[$r]="127.0.0.1:$port"
  cat >"$d/brdfd.toml" <<EOF
[server]
listen = "${address[$r]}"
[storage]
database = "$d/brdfd.db"
[meter]
port = "$d/pr650"
pacing_ms = 10
quiet_gap_ms = 20
# brdf-sim's meter, for the estimates (docs/pr650.md, "How long a reading takes")
overhead_ms = 1000
adaptive_reference_ms = 150
adaptive_dark_ms = 6000
adaptive_sample_ms = 650
[meter.quality]
"10" = "accept_and_flag"
[stage]
transport = "tcp"
address = "${modbus[$r]}"
detector_arm_motorized = true
[stage.axes.delta]
present = true
[rig]
name = "$r"
time_scale = $time_scale
[archive]
credentials = "$d/archive.conninfo"
retry_ms = 500
[[auth.tokens]]
name = "lab-demo"
token = "$token"
role = "operator"
EOF
  chmod 600 "$d/brdfd.toml"
  start_detached "$d/brdfd.pid" "$d/brdfd.out" "$d/brdfd.log" "$brdfd" --config "$d/brdfd.toml"
  wait_for_line "$d/brdfd.out" '^brdfd listening on' 20
  echo "lab-demo: $r: brdfd on ${address[$r]}, simulator stage on ${modbus[$r]}"
done
export BRDF_TOKEN="$token"

# A plan with a sample block per rig (the archive's catalogue).
plan_for() { # rig sample-id name material tags-json
  python3 - "$root/examples/plans/demo.json" "$@" <<'PY'
import json, sys
plan = json.load(open(sys.argv[1]))
rig, sid, name, material, tags = sys.argv[2:7]
plan["name"] = f"{name} on {rig}"
plan["sample"] = {"id": sid, "name": name, "material": material, "tags": json.loads(tags),
                  "whiteStandardId": "RS-3 #demo"}
print(json.dumps(plan))
PY
}
plan_for rig-a P-0001 "red gloss paint" paint '["glossy","red"]' >"$run/rig-a/plan.json"
plan_for rig-b F-0002 "blue felt" fabric '["matte","blue"]' >"$run/rig-b/plan.json"

say "both rigs record at the same time (prompts confirmed; the operator's actions done on the simulators)"
pids=()
for r in rig-a rig-b; do
  for ((i = 0; i < 200; i++)); do
    BRDF_ADDRESS="${address[$r]}" "$ctl" rig 2>/dev/null | grep -q '^stage: connected' && break
    sleep 0.1
  done
  session="$(BRDF_ADDRESS="${address[$r]}" "$ctl" submit "$run/$r/plan.json" --start --quiet)"
  echo "lab-demo: $r: session $session started"
  on_prompt="$(printf '%q sim-mount from-prompt --modbus %q' "$ctl" "${modbus[$r]}")"
  BRDF_ADDRESS="${address[$r]}" "$ctl" watch "$session" --auto-confirm --on-prompt "$on_prompt" \
    --exit-on-pause >"$run/$r/watch.log" 2>&1 &
  pids+=($!)
done
for p in "${pids[@]}"; do wait "$p" || die "a session did not complete; see $run/rig-*/watch.log"; done

say "each rig's archive status"
for r in rig-a rig-b; do
  for ((i = 0; i < 100; i++)); do
    BRDF_ADDRESS="${address[$r]}" "$ctl" rig | grep -q '^archive: caught up, 0 reading' && break
    sleep 0.1
  done
  printf '%s: ' "$r"
  BRDF_ADDRESS="${address[$r]}" "$ctl" rig | grep '^archive:'
done

say "what the archive holds (psql)"
psql_archive -c "SELECT s.rig, s.name, s.sample_id, s.material, array_to_string(s.tags, ',') AS tags,
  s.state, count(r.*) AS readings FROM sessions s LEFT JOIN readings r ON r.session_uuid = s.uuid
  GROUP BY s.uuid ORDER BY s.rig"
psql_archive -c "SELECT rig, name FROM sessions WHERE 'glossy' = ANY (tags)"
say "each rig's own count (sqlite3), to compare"
for r in rig-a rig-b; do
  printf '%s: %s readings\n' "$r" "$(sqlite3 "$run/$r/brdfd.db" 'SELECT count(*) FROM readings')"
done
# --- brdf-archive: the archive's read server -----------------------------------------------------
say "starting brdf-archive (the read API over the archive; stateless, so several can run)"
d="$run/archive"
(umask 077 && cp "$run/rig-a/archive.conninfo" "$d/archive.conninfo")
archive_address="127.0.0.1:$(free_port)"
archive_web="127.0.0.1:$(free_port)"
cat >"$d/brdf-archive.toml" <<EOF
[server]
listen = "$archive_address"
[archive]
credentials = "$d/archive.conninfo"
[web]
listen = "$archive_web"
[[auth.tokens]]
name = "lab-demo"
token = "$token"
role = "analyst"
EOF
chmod 600 "$d/brdf-archive.toml"
start_detached "$d/brdf-archive.pid" "$d/brdf-archive.out" "$d/brdf-archive.log" \
  "$archive_server" --config "$d/brdf-archive.toml"
wait_for_line "$d/brdf-archive.out" '^brdf-archive listening on' 20
echo "lab-demo: brdf-archive on $archive_address"
archive_url="$(awk '/^brdf-archive web explorer on/ { print $NF }' "$d/brdf-archive.out")"
echo "lab-demo: the archive in the browser (every rig's sessions, read only): $archive_url"

say "every session of both rigs, through brdf-archive (brdfctl list)"
BRDF_ADDRESS="$archive_address" "$ctl" list
say "only the paints (brdfctl list --material paint), then the matte samples (--tag matte)"
BRDF_ADDRESS="$archive_address" "$ctl" list --material paint
BRDF_ADDRESS="$archive_address" "$ctl" list --tag matte

say "each rig's session interpolated through brdf-archive, compared with the rig's own answer"
where=(--theta-i 20 --theta-o 25 --phi 150 --method nearest --every 25)
first_id() { python3 -c 'import json,sys; print(json.load(sys.stdin)["sessions"][0]["sessionId"])'; }
for r in rig-a rig-b; do
  archive_id="$(BRDF_ADDRESS="$archive_address" "$ctl" --json list --rig "$r" | first_id)"
  rig_id="$(BRDF_ADDRESS="${address[$r]}" "$ctl" --json list | first_id)"
  echo "lab-demo: $r: its session $rig_id is session $archive_id in the archive"
  BRDF_ADDRESS="$archive_address" "$ctl" interpolate "$archive_id" "${where[@]}" |
    tee "$run/$r/from-archive.txt"
  BRDF_ADDRESS="${address[$r]}" "$ctl" interpolate "$rig_id" "${where[@]}" >"$run/$r/from-rig.txt"
  # The first line names the session by its id, which differs; the rest must not.
  cmp -s <(tail -n +2 "$run/$r/from-archive.txt") <(tail -n +2 "$run/$r/from-rig.txt") ||
    die "$r: the archive's answer differs from the rig's ($run/$r/from-archive.txt, from-rig.txt)"
  echo "lab-demo: $r: the archive's answer is the rig's, byte for byte (but for the session id)"
done

cat <<EOF

lab-demo: done; everything keeps running. Stop it all: deploy/lab-demo.sh --stop
  archive: BRDF_TOKEN=$token BRDF_ADDRESS=$archive_address $ctl list   (brdf-archive)
           $archive_url in a browser, with the token above
           PGPASSWORD=… $pgbin/psql -h $run/pg -p $pg_port -U brdf -d postgres
           (the password is in $run/rig-a/archive.conninfo)
  rigs:    BRDF_TOKEN=$token BRDF_ADDRESS=${address[rig-a]} (rig-a) / ${address[rig-b]} (rig-b) $ctl rig
EOF
