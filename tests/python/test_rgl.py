"""The RGL material reader and figures of the Python client (brdf_client.rgl,
brdf_client.figures.rgl) on files written by `brdf-export --demo rgl`: the reader accepts the
spectral and the RGB file, gives the paint-like demo's BRDF at a few directions within the
bounds a white-referenced paint has, agrees between the RGB file and the spectral one in the
green channel's order of magnitude, and the figures are written; the sphere rendered from the
file is within 5 % of the one rendered from a grid export of the same session."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from brdf_client.rgl import Material  # noqa: E402
from brdf_client.figures import rgl as figures  # noqa: E402

BUILD = os.environ.get("BRDF_BUILD_DIR", os.path.join(ROOT, "build"))
TOOL = os.path.join(BUILD, "tools", "brdf-export", "brdf-export")


class RglFigures(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.path.exists(TOOL):
            raise unittest.SkipTest(f"{TOOL} not built")
        base = os.environ.get("BRDF_TEST_OUTPUT_DIR") or tempfile.mkdtemp(prefix="brdf_rgl_")
        cls.out = os.path.join(base, "rgl")
        os.makedirs(cls.out, exist_ok=True)
        for args, name in ((["rgl"], "demo.bsdf"), (["rgl", "--rgb"], "demo_rgb.bsdf"),
                           (["grid", "--reciprocity", "--steps", "3,3,6", "--nodes"], "g.npy")):
            subprocess.run([TOOL, "--demo", "--quiet"] + args + ["-o", os.path.join(cls.out, name)],
                           check=True, capture_output=True)

    def test_reader_values_and_figures(self):
        m = Material(os.path.join(self.out, "demo.bsdf"))
        self.assertEqual(len(m.channels), 101)
        d = np.radians
        f = m.brdf(d(np.array([30.0, 40, 60])), np.zeros(3), d(np.array([30.0, 20, 50])),
                   d(np.array([180.0, 150, 90])))
        # The demo paint: albedo 0.25..0.7 over π plus a small glossy lobe.
        self.assertTrue(np.all(f[:, 20:80] > 0.05) and np.all(f[:, 20:80] < 1.0), f[:, 42])
        self.assertTrue(np.all(m.brdf(d(np.array([30.0])), np.zeros(1), d(np.array([95.0])),
                                      np.zeros(1)) == 0))
        rgb = Material(os.path.join(self.out, "demo_rgb.bsdf"))
        self.assertTrue(rgb.rgb)
        g = rgb.brdf(d(np.array([30.0])), np.zeros(1), d(np.array([30.0])), d(np.array([120.0])))
        self.assertTrue(0.05 < g[0, 1] < 1.0, g)
        slices = os.path.join(self.out, "rgl_slices.png")
        sphere = os.path.join(self.out, "rgl_sphere.png")
        figures.plot_slices(m, slices)
        diff = figures.plot_sphere(m, sphere, os.path.join(self.out, "g.npy"), size=120)
        self.assertGreater(os.path.getsize(slices), 10000)
        self.assertGreater(os.path.getsize(sphere), 10000)
        self.assertLess(diff, 0.05)


if __name__ == "__main__":
    unittest.main()
