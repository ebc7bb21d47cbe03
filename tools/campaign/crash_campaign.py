#!/usr/bin/python3
"""Crash campaign: brdfd is killed with SIGKILL at random moments while it runs sessions on
brdf-sim, restarted, and its sessions resumed, until --kills kills; then the sessions run to the
end. After every kill, with the daemon dead, the SQLite file is checked for every session:

  - every planned step is present exactly once (step indexes 0 .. total_steps-1, no gap, no
    duplicate);
  - no reading lacks its step: each reading sits on a DONE step of its own kind, and each done
    measuring step has exactly one reading;
  - sessions.done_steps equals the steps done or skipped;
  - no reading seen at an earlier check is gone (committed means durable);
  - PRAGMA integrity_check answers "ok" (and foreign_key_check finds nothing).

At the end every session must be completed with as many readings as its plan asked for.
A summary line gives the kills survived, the sessions and the readings; the exit code is 0 when
every check passed, 1 when one failed, 2 for a setup problem (missing binary, daemon not
starting).

  /usr/bin/python3 tools/campaign/crash_campaign.py --kills 50          # the on-demand campaign
  /usr/bin/python3 tools/campaign/crash_campaign.py --kills 5 --seed 3  # what ctest runs (crash)

Binaries: $BRDF_BUILD_DIR (or --build-dir) /daemon/brdfd and /tools/brdf-sim/brdf-sim. Python:
Debian's /usr/bin/python3 with python3-grpcio and python3-protobuf (the brdf_client package of
clients/python talks to brdfd; tools/check/modbus_probe.py plays the operator at the rig).
"""

import argparse
import os
import queue
import random
import secrets
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, os.path.join(ROOT, "tools", "check"))

CONTROL_UNIT = 100  # brdf-sim's control unit; register 0: 0 sample, 1 white, 2 dark
MOUNTED_REGISTER = 0

# A small sample-rotation plan: a reference and a dark per detector position (prompts: mount the
# white, close the shutter, mount the sample), moves and samples; ~25 readings.
PLAN = {
    "name": "crash campaign",
    "sampleRotation": {
        "delta": {"start": 30, "stop": 50, "step": 20},
        "alpha": {"start": 0, "stop": 20, "step": 20},
        "beta": {"step": 60},
    },
    "reference": {"perDetectorPosition": True},
    "dark": {"withEachReference": True},
    "measurement": {"integrationMs": 200, "averages": 1},
    "retry": {"maxAttempts": 3, "backoffMs": 50},
}


class SetupError(Exception):
    """The campaign could not run (not a finding about the daemon)."""


class _Lines:
    """A process' stdout lines, read on a thread so a wait can time out."""

    def __init__(self, stream):
        self.q = queue.Queue()
        threading.Thread(target=self._pump, args=(stream,), daemon=True).start()

    def _pump(self, stream):
        for line in stream:
            self.q.put(line.rstrip("\n"))
        self.q.put(None)

    def next(self, deadline):
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError("no line in time")
        line = self.q.get(timeout=left)
        if line is None:
            raise EOFError("the process closed its stdout")
        return line


class Campaign:
    def __init__(self, args):
        self.args = args
        self.rng = random.Random(args.seed)
        build = args.build_dir or os.environ.get("BRDF_BUILD_DIR") or os.path.join(ROOT, "build")
        self.brdfd = os.path.join(build, "daemon", "brdfd")
        self.sim_bin = os.path.join(build, "tools", "brdf-sim", "brdf-sim")
        for b in (self.brdfd, self.sim_bin):
            if not os.access(b, os.X_OK):
                raise SetupError(f"{b} is not built (cmake --build <dir> --target brdfd brdf-sim)")
        self.dir = tempfile.mkdtemp(prefix="brdf_crash_")
        self.db = os.path.join(self.dir, "brdfd.db")
        self.token = secrets.token_hex(16)
        self.sim = self.daemon = None
        self.client = None
        self.daemon_lines = None
        self.modbus = None
        # What the checks found and counted.
        self.failures = []
        self.kills = 0
        self.checks = 0
        self.seen_readings = {}  # session id -> set of reading ids seen at an earlier check
        self.sessions = []       # session ids submitted, in order
        self.planned = {}        # session id -> readings its plan asks for
        self.completed = set()   # session ids seen completed

    # --- Processes -----------------------------------------------------------------------------

    def _spawn(self, argv, log_name):
        log = open(os.path.join(self.dir, log_name), "a", encoding="utf-8")  # pylint: disable=consider-using-with
        try:
            return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=log, text=True,  # pylint: disable=consider-using-with
                                    start_new_session=True)
        finally:
            log.close()

    def start_sim(self):
        self.sim = self._spawn([self.sim_bin, "--time-scale", str(self.args.time_scale), "--seed",
                                str(self.args.seed), "--wake-window", "0", "--no-pacing",
                                "--modbus-port", "0", "--log-level", "warn"], "sim.log")
        lines = _Lines(self.sim.stdout)
        deadline = time.monotonic() + 30
        pr650 = host = port = None
        try:
            while True:
                key, _, value = lines.next(deadline).partition(" ")
                if key == "pr650":
                    pr650 = value
                elif key == "modbus-tcp":
                    host, _, port = value.rpartition(":")
                elif key == "ready":
                    break
        except (TimeoutError, EOFError) as e:
            raise SetupError(f"brdf-sim did not get ready: {e}; see {self.dir}/sim.log") from e
        import modbus_probe  # pylint: disable=import-outside-toplevel
        self.modbus = modbus_probe.Client(host, int(port), 2.0)
        # brdfd's configuration: fast meter and stage timings for the scaled simulator, the
        # default quality policy (darks pass on it), one operator token.
        axes = "".join(f"[stage.axes.{n}]\nspeed_deg_s = 30\n" for n in ("alpha", "beta", "delta"))
        with open(os.path.join(self.dir, "brdfd.toml"), "w", encoding="utf-8") as f:
            f.write(f"""[server]
listen = "127.0.0.1:0"
[storage]
database = "{self.db}"
[meter]
port = "{pr650}"
pacing_ms = 5
quiet_gap_ms = 20
reply_timeout_ms = 1000
measurement_timeout_ms = 3000
wake_attempts = 3
overhead_ms = 1000
adaptive_reference_ms = 150
adaptive_dark_ms = 6000
adaptive_sample_ms = 650
[stage]
transport = "tcp"
address = "{host}:{port}"
response_timeout_ms = 500
detector_arm_motorized = true
{axes}
[[auth.tokens]]
name = "crash-campaign"
token = "{self.token}"
role = "operator"
[log]
level = "info"
""")

    def start_daemon(self):
        import brdf_client  # pylint: disable=import-outside-toplevel
        self.daemon = self._spawn([self.brdfd, "--config", os.path.join(self.dir, "brdfd.toml")],
                                  "brdfd.log")
        self.daemon_lines = _Lines(self.daemon.stdout)
        deadline = time.monotonic() + 30
        try:
            while True:
                line = self.daemon_lines.next(deadline)
                if line.startswith("brdfd listening on "):
                    address = line[len("brdfd listening on "):].strip()
                    break
        except (TimeoutError, EOFError) as e:
            raise SetupError(f"brdfd did not start: {e}; see {self.dir}/brdfd.log") from e
        self.client = brdf_client.BrdfClient(address, self.token, timeout=10)
        # A kill can land while SubmitPlan commits: the session then exists without the campaign
        # having seen its id. Every session the daemon knows is the campaign's to finish.
        for s in sorted(self.client.list_sessions(), key=lambda x: int(x.session_id)):
            if s.session_id not in self.planned:
                self.sessions.append(s.session_id)
                self.planned[s.session_id] = (s.summary.sample_readings +
                                              s.summary.reference_readings +
                                              s.summary.dark_readings)
        self.sessions.sort(key=int)

    def kill_daemon(self):
        if self.client is not None:
            self.client.close()
            self.client = None
        self.daemon.send_signal(signal.SIGKILL)
        self.daemon.wait()
        self.daemon.stdout.close()
        self.daemon = None
        self.kills += 1

    def stop_all(self):
        if self.client is not None:
            self.client.close()
        for proc in (self.daemon, self.sim):
            if proc is None or proc.poll() is not None:
                continue
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if self.modbus is not None:
            self.modbus.close()

    # --- The operator --------------------------------------------------------------------------

    def operate(self, until):
        """Plays the operator until `until` (monotonic): answers prompts after doing what they ask
        on the simulator, resumes paused sessions, submits the next session when one completes
        (while kills remain). Returns when the time is up or every session is done."""
        import brdf_client  # pylint: disable=import-outside-toplevel
        pb, plan_pb = brdf_client.brdf_pb2, brdf_client.plan_pb2
        mount = {plan_pb.PROMPT_KIND_MOUNT_WHITE: 1, plan_pb.PROMPT_KIND_MOUNT_SAMPLE: 0,
                 plan_pb.PROMPT_KIND_CLOSE_SHUTTER: 2}
        while time.monotonic() < until:
            try:
                incomplete = [x for x in self.sessions if x not in self.completed]
                if not incomplete:
                    if self.kills >= self.args.kills:
                        return
                    s = self.client.submit_plan(PLAN, start_now=True)
                    self.sessions.append(s.session_id)
                    self.planned[s.session_id] = (s.summary.sample_readings +
                                                  s.summary.reference_readings +
                                                  s.summary.dark_readings)
                    incomplete = [s.session_id]
                for current in incomplete:
                    s = self.client.get_session(current)
                    if s.state == pb.SESSION_STATE_COMPLETED:
                        self.completed.add(current)
                    elif s.state == pb.SESSION_STATE_PAUSED:
                        self.client.resume(current)
                    elif s.state == pb.SESSION_STATE_QUEUED:
                        self.client.start(current)  # nothing starts by itself after a restart
                    elif (s.state == pb.SESSION_STATE_AWAITING_OPERATOR
                          and s.HasField("pending_prompt")):
                        p = s.pending_prompt
                        if p.kind in mount:
                            self.modbus.write(CONTROL_UNIT, MOUNTED_REGISTER, [mount[p.kind]])
                        self.client.answer_prompt(current, p.step_index, note="crash campaign")
                    elif s.state in (pb.SESSION_STATE_ABORTED, pb.SESSION_STATE_FAILED):
                        self.fail(f"session {current} ended {pb.SessionState.Name(s.state)}: "
                                  f"{s.end_reason}")
                        return
            except brdf_client.BrdfError as e:
                # A refused verb (the state moved on meanwhile) is retried at the next round.
                if e.code.name != "FAILED_PRECONDITION":
                    self.log(f"operator: {e}")
            time.sleep(0.02)

    # --- Checks --------------------------------------------------------------------------------

    def fail(self, what):
        self.failures.append(what)
        self.log("FAIL " + what)

    def log(self, text):
        if self.args.verbose:
            print(f"[{time.strftime('%H:%M:%S')}] {text}", flush=True)

    def check_database(self, final=False):
        """The checks of the module docstring, on the file as the dead daemon left it."""
        self.checks += 1
        # Read-only: a writable connection would checkpoint and delete the WAL on close, and the
        # restarted daemon must find the file exactly as the crash left it.
        db = sqlite3.connect(f"file:{self.db}?mode=ro", uri=True)
        try:
            ic = db.execute("PRAGMA integrity_check").fetchall()
            if ic != [("ok",)]:
                self.fail(f"kill {self.kills}: integrity_check: {ic}")
            fk = db.execute("PRAGMA foreign_key_check").fetchall()
            if fk:
                self.fail(f"kill {self.kills}: foreign_key_check: {fk}")
            rows = db.execute("SELECT id, state, total_steps, done_steps FROM sessions").fetchall()
            for sid, state, total, done_recorded in rows:
                key = str(sid)
                where = f"kill {self.kills}, session {sid}"
                idx = [r[0] for r in db.execute(
                    "SELECT step_index FROM steps WHERE session_id = ? ORDER BY step_index", (sid,))]
                if idx != list(range(total)):
                    self.fail(f"{where}: steps are not exactly 0..{total - 1} once each "
                              f"({len(idx)} rows)")
                orphans = db.execute(
                    "SELECT COUNT(*) FROM readings r LEFT JOIN steps s ON s.session_id = "
                    "r.session_id AND s.step_index = r.step_index WHERE r.session_id = ? AND "
                    "(s.state IS NULL OR s.state != 'done' OR s.kind != r.kind)", (sid,)).fetchone()[0]
                if orphans:
                    self.fail(f"{where}: {orphans} reading(s) without a done step of their kind")
                missing = db.execute(
                    "SELECT COUNT(*) FROM steps s WHERE s.session_id = ? AND s.state = 'done' AND "
                    "s.kind IN ('reference', 'dark', 'sample') AND (SELECT COUNT(*) FROM readings "
                    "r WHERE r.session_id = s.session_id AND r.step_index = s.step_index) != 1",
                    (sid,)).fetchone()[0]
                if missing:
                    self.fail(f"{where}: {missing} done measuring step(s) without exactly one reading")
                finished = db.execute(
                    "SELECT COUNT(*) FROM steps WHERE session_id = ? AND state IN ('done', 'skipped')",
                    (sid,)).fetchone()[0]
                if finished != done_recorded:
                    self.fail(f"{where}: done_steps {done_recorded} but {finished} steps finished")
                ids = {r[0] for r in db.execute("SELECT id FROM readings WHERE session_id = ?",
                                                (sid,))}
                lost = self.seen_readings.get(key, set()) - ids
                if lost:
                    self.fail(f"{where}: {len(lost)} reading(s) seen earlier are gone")
                self.seen_readings[key] = ids
                if final:
                    if state != "completed":
                        self.fail(f"session {sid} ended {state}, not completed")
                    if key in self.planned and len(ids) != self.planned[key]:
                        self.fail(f"session {sid}: {len(ids)} readings, the plan asks for "
                                  f"{self.planned[key]}")
        finally:
            db.close()

    # --- The campaign --------------------------------------------------------------------------

    def run(self):
        started = time.monotonic()
        self.start_sim()
        self.start_daemon()
        while self.kills < self.args.kills:
            delay = self.rng.uniform(self.args.min_delay, self.args.max_delay)
            self.operate(time.monotonic() + delay)
            if self.failures:
                break
            self.kill_daemon()
            self.check_database()
            self.log(f"kill {self.kills} after {delay:.2f} s: {len(self.sessions)} session(s), "
                     f"{sum(len(v) for v in self.seen_readings.values())} reading(s)")
            if self.failures:
                break
            self.start_daemon()
        if not self.failures:
            # No more kills: every session runs to its end.
            self.operate(time.monotonic() + self.args.finish_timeout)
            self.stop_all()
            self.check_database(final=True)
        else:
            self.stop_all()
        elapsed = time.monotonic() - started
        readings = sum(len(v) for v in self.seen_readings.values())
        print(f"crash campaign: {self.kills} kill(s) survived, {len(self.sessions)} session(s), "
              f"{readings} reading(s), {self.checks} database check(s), "
              f"{len(self.failures)} failure(s), {elapsed:.1f} s")
        for f in self.failures:
            print("  " + f)
        return 0 if not self.failures else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--kills", type=int, default=50, help="SIGKILLs to survive (default 50)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the kill moments and the noise")
    ap.add_argument("--min-delay", type=float, default=0.2,
                    help="shortest run of the daemon before a kill, s (default 0.2)")
    ap.add_argument("--max-delay", type=float, default=2.5,
                    help="longest run of the daemon before a kill, s (default 2.5)")
    ap.add_argument("--time-scale", type=float, default=50, help="brdf-sim's time scale")
    ap.add_argument("--finish-timeout", type=float, default=120,
                    help="how long the sessions get to finish after the last kill, s")
    ap.add_argument("--build-dir", help="build directory (default $BRDF_BUILD_DIR, ./build)")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    ap.add_argument("-v", "--verbose", action="store_true", help="a line per kill")
    args = ap.parse_args()
    try:
        campaign = Campaign(args)
    except SetupError as e:
        print(f"crash campaign: {e}", file=sys.stderr)
        return 2
    try:
        code = campaign.run()
    except SetupError as e:
        print(f"crash campaign: {e}", file=sys.stderr)
        campaign.stop_all()
        code = 2
    if args.keep or code != 0:
        print(f"files (database, logs): {campaign.dir}")
    else:
        shutil.rmtree(campaign.dir, ignore_errors=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
