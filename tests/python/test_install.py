"""brdf_client installs as the README says, offline, into a fresh virtual environment made with
Debian's python3, and works from there (the ctest fixture of the README and notebook tests).

    /usr/bin/python3 -m venv --system-site-packages VENV
    VENV/bin/pip install --no-build-isolation --no-deps ./clients/python
    VENV/bin/python -m ipykernel install --sys-prefix      (the notebooks' kernel: this python)

Then, from a folder outside the repository (so the checkout cannot shadow the install) and
without BRDF_PY_STUBS: the package imports from the venv's site-packages, with the stubs made at
install time, the .proto files of this checkout (same digest), its version in both the metadata
and the module, py.typed; `python -m brdf_client` says the version and the API; the build left
nothing untracked in the source tree. VENV is $BRDF_PY_VENV (CMake: the build's
tests/python/venv), made afresh each run.
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
CLIENT = os.path.join(ROOT, "clients", "python")
SYSTEM_PYTHON = os.environ.get("BRDF_SYSTEM_PYTHON3", "/usr/bin/python3")
VENV = os.environ.get("BRDF_PY_VENV") or os.path.join(tempfile.gettempdir(), "brdf_client_venv")


def venv_env():
    """The environment a user has: no stubs directory of the build, no index to reach."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("BRDF_PY_STUBS", "BRDF_PROTO_ROOT", "PYTHONPATH", "PYTHONHOME")}
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    return env


def run(args, cwd=None):
    done = subprocess.run(args, cwd=cwd, env=venv_env(), capture_output=True, text=True,
                          check=False, timeout=600)
    if done.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {done.returncode}:\n{done.stdout[-3000:]}"
                             f"\n{done.stderr[-3000:]}")
    return done.stdout


def repository_digest():
    """The digest brdf_client computes, here from the checkout's proto/ (a plain import)."""
    code = ("import sys; sys.path.insert(0, sys.argv[1]); from brdf_client import _stubs; "
            "print(_stubs.proto_digest())")
    env = dict(os.environ, BRDF_PROTO_ROOT=os.path.join(ROOT, "proto"))
    return subprocess.run([SYSTEM_PYTHON, "-c", code, CLIENT], env=env, capture_output=True,
                          text=True, check=True, timeout=120).stdout.strip()


class Install(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(VENV, ignore_errors=True)
        run([SYSTEM_PYTHON, "-m", "venv", "--system-site-packages", VENV])
        cls.python = os.path.join(VENV, "bin", "python")
        cls.pip_output = run([cls.python, "-m", "pip", "install", "--no-build-isolation",
                              "--no-deps", CLIENT])
        run([cls.python, "-m", "ipykernel", "install", "--sys-prefix"])
        cls.outside = tempfile.mkdtemp(prefix="brdf_install_")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.outside, ignore_errors=True)

    def in_venv(self, code):
        return run([self.python, "-c", code], cwd=self.outside)

    def test_imports_the_installed_package_with_its_stubs(self):
        code = ("import json, brdf_client, importlib.metadata as m; "
                "print(json.dumps(dict(brdf_client.about(), file=brdf_client.__file__, "
                "dist=m.version('brdf-client'))))")
        info = json.loads(self.in_venv(code))
        site = os.path.join(os.path.realpath(VENV), "lib")
        self.assertTrue(os.path.realpath(info["file"]).startswith(site), info["file"])
        self.assertTrue(info["stubs"].endswith(os.path.join("brdf_client", "_generated")),
                        info["stubs"])
        self.assertTrue(os.path.realpath(info["stubs"]).startswith(site))
        self.assertEqual(info["proto_package"], "brdf.v1")
        self.assertEqual(info["proto_digest"], repository_digest())
        version = {}
        with open(os.path.join(CLIENT, "brdf_client", "_version.py"), encoding="utf-8") as f:
            exec(f.read(), version)  # pylint: disable=exec-used
        self.assertEqual(info["version"], version["__version__"])
        self.assertEqual(info["dist"], version["__version__"])
        package = os.path.dirname(info["file"])
        for name in ("py.typed", "generate_stubs.sh", os.path.join("proto", "brdf", "v1",
                                                                   "brdf.proto")):
            self.assertTrue(os.path.isfile(os.path.join(package, name)), name)

    def test_says_its_version_and_api(self):
        out = run([self.python, "-m", "brdf_client", "--version"], cwd=self.outside)
        self.assertRegex(out, r"^brdf_client \d+\.\d+\.\d+: API brdf\.v1 \(\.proto sha256 "
                              r"[0-9a-f]{12}\)")

    def test_labelled_stack_and_kernel_are_there(self):
        out = self.in_venv("import pandas, xarray, tqdm, brdf_client.reading_tables, "
                           "brdf_client.grid_datasets; from jupyter_client.kernelspec import "
                           "KernelSpecManager as K; print(K().get_kernel_spec('python3').argv[0])")
        self.assertEqual(os.path.realpath(out.strip()), os.path.realpath(self.python))

    def test_the_build_leaves_nothing_untracked(self):
        if shutil.which("git") is None or not os.path.exists(os.path.join(ROOT, ".git")):
            self.skipTest("not a git checkout")
        leftovers = [p for p in ("build", "brdf_client.egg-info", "brdf_client/_generated",
                                 "brdf_client/proto") if os.path.exists(os.path.join(CLIENT, p))]
        self.assertIn("build", leftovers)  # the in-tree build pip just ran
        status = subprocess.run(["git", "-C", ROOT, "status", "--porcelain",
                                 "--untracked-files=all", "--"] +
                                [f"clients/python/{p}" for p in leftovers],
                                capture_output=True, text=True, check=True).stdout
        self.assertEqual(status, "", "the build left files git would show")


if __name__ == "__main__":
    unittest.main()
