"""clients/python/README.md's first example, run as written on brdf-sim + brdfd.

The example is taken from the README (its first ```python block) and executed with the
environment the quick start prints (BRDF_ADDRESS, BRDF_TOKEN, BRDF_SIM_MODBUS, brdfctl on PATH)
from the repository's root, as a user pastes it. Then: the demo session completed (its prompts
answered by the example's on_prompt), and the interpolation the README shows as "ok" is ok.
Exit code 77 (ctest: skipped) when brdfd or brdf-sim is not built.
"""

import contextlib
import io
import os
import re
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, HERE)

import live_rig  # noqa: E402
from brdf_client import names  # noqa: E402


def first_python_block(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    match = re.search(r"```python\n(.*?)```", text, re.S)
    if not match:
        raise AssertionError(f"no ```python block in {path}")
    return match.group(1)


class ReadmeExamples(unittest.TestCase):
    def test_first_example_runs_as_written_on_the_demo_plan(self):
        sim, daemon = live_rig.binaries()
        code = first_python_block(os.path.join(ROOT, "clients", "python", "README.md"))
        self.assertIn("on_prompt=act", code)
        with live_rig.LiveRig(sim, daemon) as rig:
            env = {
                "BRDF_ADDRESS": rig.address,
                "BRDF_TOKEN": rig.operator_token,
                "BRDF_SIM_MODBUS": f"{rig.modbus_host}:{rig.modbus_port}",
                "PATH": os.path.join(live_rig.build_dir(), "tools", "brdfctl") + os.pathsep +
                        os.environ.get("PATH", ""),
            }
            saved_env, saved_cwd = dict(os.environ), os.getcwd()
            os.environ.update(env)
            os.chdir(ROOT)
            namespace = {"__name__": "readme_example"}
            out = io.StringIO()
            try:
                with contextlib.redirect_stdout(out):
                    exec(compile(code, "clients/python/README.md", "exec"), namespace)
            except Exception:
                print(out.getvalue()[-4000:], file=sys.stderr)
                print(rig.log("brdfd")[-4000:], file=sys.stderr)
                raise
            finally:
                os.chdir(saved_cwd)
                os.environ.clear()
                os.environ.update(saved_env)
        self.assertEqual(names.state_name(namespace["final"].state), "completed")
        self.assertIn("operator:", out.getvalue())  # the prompts went through act()
        r = namespace["r"]
        self.assertEqual(r.status, "ok")  # as the README's comment says
        self.assertEqual(r.spectrum.shape, (101,))
        self.assertEqual(len(r.vertex_ids), 4)
        self.assertEqual(namespace["b"].spectra.shape, (2, 101))


if __name__ == "__main__":
    if None in live_rig.binaries():
        print("brdfd or brdf-sim is not built: skipped", file=sys.stderr)
        sys.exit(77)
    unittest.main()
