"""clients/python/README.md's examples, run as written on brdf-sim + brdfd, in the virtual
environment the README's install makes (python_client_install, $BRDF_PY_VENV).

The first two ```python blocks are run in order, in one interpreter of that venv (not the
checkout: the package as installed), from the repository's root, with the environment the
quick start prints (BRDF_ADDRESS, BRDF_TOKEN, BRDF_SIM_MODBUS, brdfctl on PATH) — as a user
pastes them (readme_harness.py). Then: the demo session completed (its prompts answered by the
example's on_prompt), the interpolation the README shows as "ok" is ok; the labelled example's
grid is the .npy it kept, cell for cell, with the sidecar's unit and fill counts per cell.
Exit code 77 (ctest: skipped) when brdfd or brdf-sim is not built.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)

import live_rig  # noqa: E402

ANALYSIS = os.path.join(ROOT, "run", "analysis")
FILES = ("grid.npy", "grid.npy.json", "grid.nc")


class ReadmeExamples(unittest.TestCase):
    def test_examples_run_as_written_in_the_installed_package(self):
        venv, python = live_rig.venv_python()
        sim, daemon = live_rig.binaries()
        out = tempfile.mkdtemp(prefix="brdf_readme_")
        self.addCleanup(shutil.rmtree, out, True)
        with live_rig.LiveRig(sim, daemon) as rig:
            env = {k: v for k, v in os.environ.items()
                   if k not in ("BRDF_PY_STUBS", "PYTHONPATH")}
            env.update({
                "BRDF_ADDRESS": rig.address,
                "BRDF_TOKEN": rig.operator_token,
                "BRDF_SIM_MODBUS": f"{rig.modbus_host}:{rig.modbus_port}",
                "PATH": os.path.join(live_rig.build_dir(), "tools", "brdfctl") + os.pathsep +
                        env.get("PATH", ""),
            })
            existed = {f for f in FILES if os.path.exists(os.path.join(ANALYSIS, f))}
            try:
                done = subprocess.run(
                    [python, os.path.join(HERE, "readme_harness.py"),
                     os.path.join(ROOT, "clients", "python", "README.md"),
                     os.path.join(out, "result.json")],
                    cwd=ROOT, env=env, capture_output=True, text=True, timeout=280, check=False)
            finally:
                for f in set(FILES) - existed:  # the example's files, not a user's
                    if os.path.exists(os.path.join(ANALYSIS, f)):
                        os.remove(os.path.join(ANALYSIS, f))
            if done.returncode != 0:
                print(rig.log("brdfd")[-3000:], file=sys.stderr)
                self.fail(f"the README's examples failed:\n{done.stderr[-6000:]}")
        with open(os.path.join(out, "result.json"), encoding="utf-8") as f:
            result = json.load(f)
        first, labelled = result["block1"], result["block2"]
        self.assertEqual(first["state"], "completed")
        self.assertTrue(first["acted"])  # the prompts went through act()
        self.assertEqual(first["r_status"], "ok")  # as the README's comment says
        self.assertEqual(first["r_shape"], [101])
        self.assertEqual(first["r_vertices"], 4)
        self.assertEqual(first["b_shape"], [2, 101])
        self.assertTrue(os.path.realpath(labelled["module_file"]).startswith(
            os.path.realpath(venv)), labelled["module_file"])
        self.assertGreater(labelled["rows"], 0)
        self.assertEqual(labelled["kinds"], ["dark", "reference", "sample"])
        self.assertEqual(labelled["f_dims"], ["reading", "wavelength"])
        self.assertEqual(labelled["grid_dims"], ["theta_i", "theta_o", "phi", "wavelength"])
        self.assertTrue(labelled["grid_equals_npy"])
        self.assertTrue(labelled["same_equals_npy"])
        self.assertEqual(labelled["provenance_counts"], labelled["sidecar_fill"])
        self.assertEqual(labelled["grid_unit"], labelled["sidecar_unit"])
        self.assertEqual(labelled["r_dims"], ["wavelength"])
        self.assertEqual(labelled["b_dims"], ["direction", "wavelength"])
        self.assertEqual(labelled["hd_dims"], ["theta_h", "theta_d", "phi_d", "wavelength"])


if __name__ == "__main__":
    if None in live_rig.binaries():
        print("brdfd or brdf-sim is not built: skipped", file=sys.stderr)
        sys.exit(77)
    unittest.main()
