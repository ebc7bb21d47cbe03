"""brdf-sim and brdfd as processes, for tests of brdf_client against a running daemon.

LiveRig starts the simulated rig (fast: large time scale, no serial pacing, no PR-650 wake-up
window, any free Modbus port), writes a brdfd configuration for it (any free gRPC port, a
database in a temporary directory, an operator and an analyst token, a motorized detector arm as
the simulator has one) and starts brdfd, then waits for "brdfd listening on <address>". The
operator's manual actions are done on the simulator through its Modbus control unit (unit 100,
register 0: 0 sample, 1 white, 2 dark; tools/brdf-sim/stage/control_map.h) with the plain-socket
Modbus client of tools/check/modbus_probe.py.
"""

import os
import queue
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools", "check"))

import modbus_probe  # noqa: E402  pylint: disable=wrong-import-position

CONTROL_UNIT = 100
MOUNTED_TARGET = 0  # register: 0 sample, 1 white reference, 2 dark (shutter closed)
MOUNTED = {"sample": 0, "white": 1, "dark": 2}
TIME_SCALE = 100


def build_dir():
    return os.environ.get("BRDF_BUILD_DIR") or os.path.join(ROOT, "build")


def binaries():
    """(brdf-sim, brdfd) paths in the build directory; missing ones are None."""
    b = build_dir()
    sim = os.path.join(b, "tools", "brdf-sim", "brdf-sim")
    daemon = os.path.join(b, "daemon", "brdfd")
    return (sim if os.access(sim, os.X_OK) else None,
            daemon if os.access(daemon, os.X_OK) else None)


class _Lines:
    """Reads a process' stdout on a thread, so that waiting for a line can time out."""

    def __init__(self, stream):
        self.lines = queue.Queue()
        self.thread = threading.Thread(target=self._pump, args=(stream,), daemon=True)
        self.thread.start()

    def _pump(self, stream):
        for line in stream:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def next(self, deadline):
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError("no line in time")
        line = self.lines.get(timeout=left)
        if line is None:
            raise EOFError("the process closed its stdout")
        return line


class LiveRig:
    """A running brdf-sim + brdfd pair; use as a context manager or call start()/stop()."""

    def __init__(self, sim_path, daemon_path, white_reflectance=0.99, seed=7, sim_args=(),
                 extra_config="", meter="pr650"):
        """seed, sim_args: brdf-sim's --seed and further flags (a material, error sources);
        extra_config: TOML appended to brdfd's configuration (e.g. an [uncertainty] table);
        meter: brdf-sim's --meter and brdfd's [meter] model (pr650; pr670, pr655: 201 or 101
        bands; cs2000, cs2000a, cs3000: 401 bands)."""
        self.sim_path = sim_path
        self.daemon_path = daemon_path
        self.white_reflectance = white_reflectance
        self.seed = seed
        self.sim_args = list(sim_args)
        self.extra_config = extra_config
        self.meter = meter
        self.sample_extra = ""  # more [sample] keys, e.g. "white_reflectance_uncertainty = 0.005"
        self.dir = tempfile.mkdtemp(prefix="brdf_pyclient_")
        self.operator_token = secrets.token_hex(16)
        self.analyst_token = secrets.token_hex(16)
        self.sim = self.daemon = None
        self.pr650 = self.modbus_host = self.address = None
        self.modbus_port = 0

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc):
        self.stop()

    def _spawn(self, args, log_name):
        with open(os.path.join(self.dir, log_name), "w", encoding="utf-8") as log:
            return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=log, text=True,  # pylint: disable=consider-using-with
                                    start_new_session=True)

    def log(self, name):
        """The stderr of "sim" or "brdfd" so far (for failure messages)."""
        try:
            with open(os.path.join(self.dir, f"{name}.log"), encoding="utf-8") as f:
                return f.read()[-4000:]
        except OSError:
            return ""

    def start(self, timeout=30.0):
        self.sim = self._spawn([self.sim_path, "--time-scale", str(TIME_SCALE), "--seed",
                                str(self.seed), "--wake-window", "0", "--no-pacing",
                                "--modbus-port", "0", "--log-level", "warn",
                                "--meter", self.meter] + self.sim_args,
                               "sim.log")
        lines = _Lines(self.sim.stdout)
        deadline = time.monotonic() + timeout
        try:
            while True:
                line = lines.next(deadline)
                key, _, value = line.partition(" ")
                if key == self.meter:  # the meter's port line is named after --meter
                    self.pr650 = value
                elif key == "modbus-tcp":
                    self.modbus_host, _, port = value.rpartition(":")
                    self.modbus_port = int(port)
                elif key == "ready":
                    break
        except (TimeoutError, EOFError) as e:
            self.stop()
            raise RuntimeError(f"brdf-sim did not get ready ({e}): {self.log('sim')}") from e

        config = os.path.join(self.dir, "brdfd.toml")
        with open(config, "w", encoding="utf-8") as f:
            f.write(self.config_text())
        self.daemon = self._spawn([self.daemon_path, "--config", config], "brdfd.log")
        lines = _Lines(self.daemon.stdout)
        deadline = time.monotonic() + timeout
        try:
            while True:
                line = lines.next(deadline)
                if line.startswith("brdfd listening on "):
                    self.address = line[len("brdfd listening on "):].strip()
                    break
        except (TimeoutError, EOFError) as e:
            self.stop()
            raise RuntimeError(f"brdfd did not start listening ({e}): {self.log('brdfd')}") from e

    def config_text(self):
        """brdfd's configuration for this simulator (daemon/config/config.h documents the keys)."""
        axes = ""
        for name, unit in (("alpha", 1), ("beta", 2), ("delta", 4)):
            axes += (f"[stage.axes.{name}]\nunit_id = {unit}\nspeed_deg_s = 30\n"
                     + ("present = true\n" if name == "delta" else ""))
        # The PR-655/670's commands are typed a character at a time: keep the gap short.
        typed = "char_gap_ms = 1\n" if self.meter in ("pr655", "pr670") else ""
        return f"""# brdfd for brdf-sim, written by tests/python/live_rig.py
[server]
listen = "127.0.0.1:0"

[storage]
database = "{self.dir}/brdfd.db"

[meter]
model = "{self.meter}"
port = "{self.pr650}"
{typed}pacing_ms = 5
quiet_gap_ms = 20
reply_timeout_ms = 1000
measurement_timeout_ms = 5000
# brdf-sim's meter, for the estimates (docs/pr650.md, "How long a reading takes")
overhead_ms = 1000
adaptive_reference_ms = 150
adaptive_dark_ms = 6000
adaptive_sample_ms = 650
[meter.quality]
# A dark reading (lamp shuttered) is weak light by nature: the simulator, like a PR-650, answers
# quality 10 there. Keep it, flagged, instead of failing the step.
"10" = "accept_and_flag"

[stage]
transport = "tcp"
address = "{self.modbus_host}:{self.modbus_port}"
response_timeout_ms = 500
detector_arm_motorized = true
{axes}
[sample]
white_reflectance = {self.white_reflectance}
{self.sample_extra}
[[auth.tokens]]
name = "test-operator"
token = "{self.operator_token}"
role = "operator"

[[auth.tokens]]
name = "test-analyst"
token = "{self.analyst_token}"
role = "analyst"

[log]
level = "warn"
""" + self.extra_config

    def set_mounted(self, what):
        """Puts "sample", "white" or "dark" in front of the simulated meter (the control unit)."""
        client = modbus_probe.Client(self.modbus_host, self.modbus_port, 2.0)
        try:
            client.write(CONTROL_UNIT, MOUNTED_TARGET, [MOUNTED[what]])
        finally:
            client.close()

    def mounted(self):
        """What the simulator has mounted now ("sample", "white" or "dark")."""
        client = modbus_probe.Client(self.modbus_host, self.modbus_port, 2.0)
        try:
            value = client.read(CONTROL_UNIT, MOUNTED_TARGET, 1)[0]
        finally:
            client.close()
        return {v: k for k, v in MOUNTED.items()}[value]

    def stop(self):
        for proc in (self.daemon, self.sim):
            if proc is None or proc.poll() is not None:
                continue
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        for proc in (self.daemon, self.sim):
            if proc is not None and proc.stdout:
                proc.stdout.close()
        self.daemon = self.sim = None

    def cleanup(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def run_demo(rig, timeout=240):
    """Submits the quick start's plan (examples/plans/demo.json) on `rig`, answers its prompts on
    the simulator and waits for it to complete; returns the session id. RuntimeError otherwise."""
    sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
    from brdf_client import BrdfClient, names  # pylint: disable=import-outside-toplevel

    with BrdfClient(rig.address, token=rig.operator_token) as brdf:
        session = brdf.submit_plan(os.path.join(ROOT, "examples", "plans", "demo.json"),
                                   start_now=True)

        def act(prompt):
            kind = names.prompt_kind_name(prompt.kind)
            rig.set_mounted("white" if kind == "mount_white" else
                            "dark" if kind == "close_shutter" else "sample")

        final = brdf.wait(session.session_id, on_prompt=act, timeout=timeout, progress=False)
        if names.state_name(final.state) != "completed":
            raise RuntimeError(f"the demo session ended {names.state_name(final.state)}: "
                               f"{rig.log('brdfd')}")
        return session.session_id


def venv_python():
    """The python of the venv the README's install made (python_client_install, $BRDF_PY_VENV);
    AssertionError when it is not there."""
    venv = os.environ.get("BRDF_PY_VENV") or os.path.join(tempfile.gettempdir(),
                                                          "brdf_client_venv")
    python = os.path.join(venv, "bin", "python")
    if not os.access(python, os.X_OK):
        raise AssertionError(f"no venv at {venv}: run the test python_client_install first "
                             "(ctest does, as this test's fixture)")
    return venv, python
