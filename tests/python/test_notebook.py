"""clients/python/examples/quickstart.ipynb, executed headless (Debian's python3-nbclient) in the
kernel of the venv the README's install makes (python_client_install, $BRDF_PY_VENV), against
brdf-sim + brdfd after the quick start's plan (examples/plans/demo.json) ran to completion.

Every cell must run without an error; the notebook draws its three figures (Figure 7, Figure 8,
the grid slice) as PNG outputs; its check of Figure 8 (the daemon's spectrum is the weighted sum
of the vertex spectra from the readings' DataArray) and its NetCDF round trip print what they
should. The executed notebook is kept in $BRDF_TEST_OUTPUT_DIR/notebook/ for a look.
Exit code 77 (ctest: skipped) when brdfd or brdf-sim is not built.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)

import live_rig  # noqa: E402

NOTEBOOK = os.path.join(ROOT, "clients", "python", "examples", "quickstart.ipynb")

# Run inside the venv's python: nbclient starts the kernel "python3", which
# `python -m ipykernel install --sys-prefix` made the venv's own.
EXECUTE = """
import sys, nbformat, nbclient
nb = nbformat.read(sys.argv[1], as_version=4)
nbclient.NotebookClient(nb, timeout=240, kernel_name="python3",
                        resources={"metadata": {"path": sys.argv[3]}}).execute()
nbformat.write(nb, sys.argv[2])
"""


def outputs(nb, kind):
    """Every output of `kind` ("image/png", "text") over the code cells, in order."""
    found = []
    for cell in nb["cells"]:
        for out in cell.get("outputs", []):
            if kind == "text" and out.get("output_type") == "stream":
                text = out["text"]
                found.append("".join(text) if isinstance(text, list) else text)
            elif kind != "text" and kind in out.get("data", {}):
                found.append(out["data"][kind])
    return found


class Notebook(unittest.TestCase):
    def test_runs_headless_and_draws_its_three_figures(self):
        venv, python = live_rig.venv_python()
        base = os.environ.get("BRDF_TEST_OUTPUT_DIR") or tempfile.mkdtemp(prefix="brdf_nb_")
        out_dir = os.path.join(base, "notebook")
        os.makedirs(out_dir, exist_ok=True)
        executed = os.path.join(out_dir, "quickstart.executed.ipynb")
        sim, daemon = live_rig.binaries()
        with live_rig.LiveRig(sim, daemon) as rig:
            session_id = live_rig.run_demo(rig)
            env = {k: v for k, v in os.environ.items()
                   if k not in ("BRDF_PY_STUBS", "PYTHONPATH", "JUPYTER_PATH")}
            env.update(BRDF_ADDRESS=rig.address, BRDF_TOKEN=rig.analyst_token,
                       BRDF_SESSION=session_id,
                       # no kernels of the user's own (~/.local/share/jupyter) in the way
                       JUPYTER_DATA_DIR=os.path.join(out_dir, "jupyter-data"),
                       JUPYTER_RUNTIME_DIR=os.path.join(out_dir, "jupyter-runtime"),
                       MPLCONFIGDIR=os.path.join(out_dir, "mplconfig"))
            done = subprocess.run([python, "-c", EXECUTE, NOTEBOOK, executed,
                                   os.path.dirname(NOTEBOOK)],
                                  env=env, capture_output=True, text=True, timeout=280,
                                  check=False)
            if done.returncode != 0:
                print(rig.log("brdfd")[-3000:], file=sys.stderr)
                self.fail(f"the notebook failed:\n{done.stderr[-8000:]}")
        with open(executed, encoding="utf-8") as f:
            nb = json.load(f)
        self.assertEqual(len(outputs(nb, "image/png")), 3, "Figure 7, Figure 8, the grid slice")
        text = "".join(outputs(nb, "text"))
        self.assertIn(f"session {session_id}: ", text)
        self.assertIn("'proto_package': 'brdf.v1'", text)
        self.assertIn(os.path.realpath(venv), os.path.realpath(re.search(
            r"'stubs': '([^']+)'", text).group(1)))  # the installed package, not the checkout
        mismatch = float(re.search(r"max f: ([0-9.eE+-]+)", text).group(1))
        self.assertLess(mismatch, 1e-9)
        self.assertIn("('theta_i', 'theta_o', 'phi', 'wavelength') sr⁻¹ True", text)
        self.assertIn("octant chain {", text)


if __name__ == "__main__":
    if None in live_rig.binaries():
        print("brdfd or brdf-sim is not built: skipped", file=sys.stderr)
        sys.exit(77)
    unittest.main()
