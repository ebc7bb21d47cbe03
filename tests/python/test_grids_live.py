"""A session on a 401-band meter end to end (issue 41, any wavelength grid): brdf-sim simulating a
Konica Minolta CS-2000 (380–780 nm every 1 nm), brdfd driving it; a small sample-rotation plan run
to completion, then everything a lab reads of it on that grid:

  the session says its grid (GetSession, ListSessions, brdfctl get and list); the Python
  client's ReadingSet has 401 bands; the readings CSV has the columns 380..780 every 1 nm; the grid
  .npy is (nθi, nθo, nφ, 401) and the grid CSV has 401 band columns; the MERL .binary and the RGL
  .bsdf (spectral: 401 wavelengths; rgb=True: colour from the 401-band grid) are valid; BiRD's
  wavelengths are the session's; Interpolate and InterpolateBatch answers have 401 values (and a
  chunk of the most results a client may ask stays under a client's default 4 MiB receive limit);
  the appearance (colour, lit sphere) renders from the 401-band spectra.

Exit code 77 (ctest: skipped) when brdfd or brdf-sim is not built.
"""

import csv
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, HERE)

import live_rig  # noqa: E402
from brdf_client import BrdfClient, brdf_pb2, names  # noqa: E402
from brdf_client.interpolation import direction_query  # noqa: E402
from brdf_client.rgl import Material  # noqa: E402
from test_live import PROMPT_ACTIONS  # noqa: E402

BANDS = 401
WAVELENGTHS = 380.0 + np.arange(BANDS)  # a CS-2000's grid: 380–780 nm every 1 nm
MERL_BYTES = 90 * 90 * 180 * 3 * 8 + 12
GRID_STEPS = {"step_theta_i": 10.0, "step_theta_o": 10.0, "step_phi": 20.0}
GRID_SHAPE = (9, 9, 9)
# A client's default receive limit (gRPC's 4 MiB), and the most results per chunk one may ask.
CLIENT_RECEIVE_LIMIT = 4 * 1024 * 1024
MAX_CHUNK = 1024
MAX_UNCERTAIN_CHUNK = 512  # with include_uncertainty (daemon/api/common.h)
# test_live.py's plan, coarser in β: fewer readings at the CS-2000's pace.
PLAN = {
    "name": "401-band session",
    "sampleDescription": "virtual paint of brdf-sim, CS-2000",
    "sampleRotation": {
        "delta": {"start": 0, "stop": 60, "step": 30},
        "alpha": {"start": 0, "stop": 40, "step": 20},
        "beta": {"step": 30},
    },
    "reference": {"perDetectorPosition": True},
    "dark": {"withEachReference": True},
    "measurement": {"integrationMs": 0, "averages": 1},
    "retry": {"maxAttempts": 3, "backoffMs": 10},
}


class Live401Bands(unittest.TestCase):  # pylint: disable=too-many-public-methods
    rig = None
    client = None
    session_id = None
    final = None
    readings = None
    out = None

    @classmethod
    def setUpClass(cls):
        sim, daemon = live_rig.binaries()
        cls.rig = live_rig.LiveRig(sim, daemon, meter="cs2000")
        cls.rig.start()
        cls.client = BrdfClient(cls.rig.address, cls.rig.operator_token)
        cls.out = tempfile.mkdtemp(prefix="brdf_grids_", dir=cls.rig.dir)
        try:
            cls.client.wait_ready(10)
            cls.session_id = cls.client.submit_plan(PLAN, start_now=True).session_id
            cls.final = cls.client.wait(cls.session_id, on_prompt=cls._act, timeout=240,
                                        stop_states=("paused",))
            if names.state_name(cls.final.state) != "completed":
                raise AssertionError(f"session ended {names.state_name(cls.final.state)}: "
                                     f"{cls.final.last_fault.reason or cls.final.end_reason}")
            cls.readings = cls.client.load_readings(cls.session_id)
        except Exception:
            print(f"brdfd log:\n{cls.rig.log('brdfd')}\nbrdf-sim log:\n{cls.rig.log('sim')}",
                  file=sys.stderr)
            cls.tearDownClass()
            raise

    @classmethod
    def _act(cls, prompt):
        what = PROMPT_ACTIONS.get(names.prompt_kind_name(prompt.kind))
        if what:
            cls.rig.set_mounted(what)

    @classmethod
    def tearDownClass(cls):
        if cls.client:
            cls.client.close()
        if cls.rig:
            cls.rig.stop()
            cls.rig.cleanup()

    def path(self, name):
        folder = os.path.join(self.out, self.id().rsplit(".", 1)[-1])
        os.makedirs(folder, exist_ok=True)
        return os.path.join(folder, name)

    @staticmethod
    def read_csv(path):
        with open(path, encoding="utf-8", newline="") as f:
            lines = [line for line in f if not line.startswith("#")]
        rows = list(csv.reader(lines))
        return rows[0], rows[1:]

    def assertGrid(self, grid, what):
        self.assertEqual((grid.start_nm, grid.step_nm, grid.count), (380.0, 1.0, BANDS), what)

    # --- the session and its readings -------------------------------------------------------------

    def test_the_session_says_its_grid(self):
        self.assertGrid(self.final.grid, "WatchSession's last state")
        self.assertGrid(self.client.get_session(self.session_id).grid, "GetSession")
        listed = [s for s in self.client.list_sessions() if s.session_id == self.session_id]
        self.assertEqual(len(listed), 1)
        self.assertGrid(listed[0].grid, "ListSessions")

    def test_brdfctl_shows_the_sessions_grid(self):
        brdfctl = os.path.join(live_rig.build_dir(), "tools", "brdfctl", "brdfctl")
        if not os.access(brdfctl, os.X_OK):
            self.skipTest("brdfctl is not built")
        common = [brdfctl, "--address", self.rig.address, "--token", self.rig.operator_token]
        got = subprocess.run(common + ["get", self.session_id], capture_output=True, text=True,
                             check=True)
        self.assertIn("wavelengths  380–780 nm every 1 nm (401 bands)", got.stdout)
        listing = subprocess.run(common + ["list"], capture_output=True, text=True, check=True)
        line = [ln for ln in listing.stdout.splitlines() if ln.startswith(self.session_id + " ")]
        self.assertEqual(len(line), 1, listing.stdout)
        self.assertIn("401 bands", line[0])

    def test_reading_set_has_401_bands(self):
        np.testing.assert_array_equal(self.readings.wavelengths, WAVELENGTHS)
        self.assertEqual(self.readings.spectra.shape, (len(self.readings.ids), BANDS))
        samples = self.readings.of_kind("sample")
        self.assertEqual(len(samples.ids), self.final.summary.sample_readings)
        self.assertTrue(np.all(np.isfinite(samples.spectra)))
        self.assertGreater(float(samples.spectra.sum()), 0)

    # --- exports ----------------------------------------------------------------------------------

    def test_readings_csv_columns_are_380_to_780_every_1_nm(self):
        for quantity in ("radiance", "brdf"):
            path = self.path(f"readings-{quantity}.csv")
            r = self.client.export(self.session_id, "csv", path, quantity=quantity)
            header, rows = self.read_csv(path)
            # BRDF (and reflectance) rows carry a standard uncertainty per band after the values.
            columns = 16 + BANDS * (2 if quantity == "brdf" else 1)
            self.assertEqual(len(header), columns, quantity)
            np.testing.assert_array_equal([float(h) for h in header[16:16 + BANDS]], WAVELENGTHS)
            if quantity == "brdf":
                self.assertEqual(header[16 + BANDS:], [f"u_{h}" for h in header[16:16 + BANDS]])
            self.assertEqual(len(rows), r.rows)
            self.assertTrue(all(len(row) == columns for row in rows))
            if quantity == "radiance":
                self.assertEqual(r.rows, len(self.readings.ids))

    def test_grid_npy_and_csv_have_401_bands(self):
        path = self.path("grid.npy")
        r = self.client.export(self.session_id, "grid", path, **GRID_STEPS)
        grid = np.load(path)
        self.assertEqual(grid.shape, GRID_SHAPE + (BANDS,))
        self.assertEqual(tuple(r.shape), grid.shape)
        self.assertEqual(r.description["shape"], list(grid.shape))
        self.assertTrue(np.all(np.isfinite(grid)), "the fill chain leaves no hole")
        text = json.dumps(r.description)
        self.assertIn("401", text)
        csv_path = self.path("grid.csv")
        c = self.client.export(self.session_id, "grid", csv_path, **GRID_STEPS)
        header, rows = self.read_csv(csv_path)
        self.assertEqual(header[:4], ["theta_i", "theta_o", "phi", "status"])
        np.testing.assert_array_equal([float(h) for h in header[4:]], WAVELENGTHS)
        self.assertEqual(len(rows), c.cells)
        # The CSV's values are the .npy's, cell for cell.
        first = np.array([float(x) for x in rows[0][4:]])
        np.testing.assert_allclose(first, grid.reshape(-1, BANDS)[0], rtol=1e-9)

    def test_merl_binary_is_valid(self):
        path = self.path("sample.binary")
        r = self.client.export(self.session_id, "merl", path)
        self.assertEqual(os.path.getsize(path), MERL_BYTES)
        dims = np.fromfile(path, dtype="<i4", count=3)
        np.testing.assert_array_equal(dims, [90, 90, 180])
        table = np.fromfile(path, dtype="<f8", offset=12).reshape(3, -1)
        missing = table[0] == -1
        self.assertEqual(int(missing.sum()), r.below_horizon_cells)
        self.assertEqual(r.unfilled_cells, 0)
        filled = table[:, ~missing]
        self.assertTrue(np.all(np.isfinite(filled)) and np.all(filled >= 0))
        self.assertGreater(float(filled.mean()), 0)

    def test_rgl_spectral_and_rgb(self):
        path = self.path("sample.bsdf")
        self.client.export(self.session_id, "rgl", path, rgl_theta_i_count=6, rgl_resolution=16)
        m = Material(path)
        np.testing.assert_array_equal(np.asarray(m.channels, dtype=float), WAVELENGTHS)
        rgb_path = self.path("sample-rgb.bsdf")
        self.client.export(self.session_id, "rgl", rgb_path, rgb=True, rgl_theta_i_count=6,
                           rgl_resolution=16)
        for p, channels in ((path, BANDS), (rgb_path, 3)):
            check = subprocess.run([sys.executable,
                                    os.path.join(ROOT, "tools", "check", "rgl_read.py"), p,
                                    "--at", "20,0,20,180"], capture_output=True, text=True)
            self.assertEqual(check.returncode, 0, check.stderr)
            mat = Material(p)
            d = np.radians
            f = mat.brdf(d(np.array([20.0, 30.0])), d(np.array([0.0, 0.0])),
                         d(np.array([20.0, 30.0])), d(np.array([180.0, 180.0])))
            self.assertEqual(f.shape, (2, channels))
            self.assertTrue(np.all(np.isfinite(f)) and np.all(f.mean(axis=1) > 0))

    def test_bird_wavelengths_are_the_sessions(self):
        path = self.path("sample-bird.json")
        r = self.client.export(self.session_id, "bird", path)
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        samples = self.readings.of_kind("sample")
        n = len(samples.ids)
        self.assertEqual(r.rows, n * BANDS)
        wl = np.array(doc["data"]["wavelength_r"]["values"]).reshape(n, BANDS)
        np.testing.assert_array_equal(wl, np.tile(WAVELENGTHS, (n, 1)))
        self.assertEqual(len(doc["data"]["BRDF"]["values"]), n * BANDS)

    # --- interpolation ----------------------------------------------------------------------------

    def test_interpolate_answers_have_401_values(self):
        # Directions just beside the sample readings': the first each method fills (the octant
        # method needs a reading in every octant around it, which this small session has only
        # inside its grid).
        samples = self.readings.of_kind("sample")
        for method in ("octant", "delaunay", "nearest"):
            answered = None
            for theta_i, theta_o, phi in samples.iso:
                res = self.client.interpolate(self.session_id, theta_i + 0.2, theta_o + 0.2,
                                              min(phi + 0.5, 180.0), method=method)
                self.assertEqual(len(res.wavelengths), BANDS, method)
                if res.ok:
                    answered = res
                    break
            self.assertIsNotNone(answered, f"{method} filled no direction beside a reading")
            self.assertEqual(len(answered.spectrum), BANDS, method)
            np.testing.assert_array_equal(answered.wavelengths, WAVELENGTHS)

    def test_interpolate_batch_answers_have_401_values(self):
        rng = np.random.default_rng(5)
        directions = np.column_stack([rng.uniform(0, 40, 1500), rng.uniform(0, 40, 1500),
                                      rng.uniform(0, 180, 1500)])
        batch = self.client.interpolate_batch(self.session_id, directions, method="nearest")
        self.assertEqual(batch.spectra.shape, (1500, BANDS))
        self.assertTrue(np.all(np.isfinite(batch.spectra)))
        # The raw chunks of the most results a client may ask: each under a client's default
        # receive limit, each result within daemon/api/common.h's ResultBytes(401).
        request = brdf_pb2.InterpolateBatchRequest(
            session_id=self.session_id, method=names.to_enum("nearest", names.METHODS, "method"),
            directions=[direction_query(d) for d in directions], chunk_size=MAX_CHUNK)
        sizes, counts = [], []
        answered = 0
        for chunk in self.client._interp.InterpolateBatch(  # pylint: disable=protected-access
                request, metadata=self.client._metadata, timeout=60):  # pylint: disable=protected-access
            sizes.append(chunk.ByteSize())
            counts.append(len(chunk.results))
            answered += len(chunk.results)
            for result in chunk.results:
                self.assertEqual(len(result.spectrum), BANDS)
                self.assertEqual(result.grid.count, BANDS)
        self.assertEqual(answered, 1500)
        self.assertLess(max(sizes), CLIENT_RECEIVE_LIMIT)
        # The chunks grow from 8 results (brdf.proto, chunk_size): the largest a result takes.
        per_result = max(size / count for size, count in zip(sizes, counts))
        print(f"\nInterpolateBatch at 401 bands: chunks of up to {max(counts)} results, at most "
              f"{max(sizes):,} B ({per_result:,.0f} B a result)", file=sys.stderr)
        self.assertLessEqual(per_result, 400 + 8 * BANDS)

    def test_interpolate_batch_with_uncertainty_stays_under_the_receive_limit(self):
        """With include_uncertainty (and the shared part, the largest form) at 401 bands, the
        daemon splits the most results a client may ask into chunks under half a client's
        receive limit, each result within common.h's ResultBytes(401, kPartsAndShared); the
        answers carry float parts of 401 values and no combined."""
        rng = np.random.default_rng(6)
        directions = np.column_stack([rng.uniform(0, 40, 1200), rng.uniform(0, 40, 1200),
                                      rng.uniform(0, 180, 1200)])
        request = brdf_pb2.InterpolateBatchRequest(
            session_id=self.session_id, method=names.to_enum("delaunay", names.METHODS, "method"),
            directions=[direction_query(d) for d in directions], chunk_size=MAX_UNCERTAIN_CHUNK,
            include_uncertainty=True, include_uncertainty_shared=True)
        sizes, counts, answered, with_parts, largest = [], [], 0, 0, 0
        for chunk in self.client._interp.InterpolateBatch(  # pylint: disable=protected-access
                request, metadata=self.client._metadata, timeout=60):  # pylint: disable=protected-access
            sizes.append(chunk.ByteSize())
            counts.append(len(chunk.results))
            answered += len(chunk.results)
            for result in chunk.results:
                if result.status != brdf_pb2.INTERPOLATION_STATUS_OK:
                    continue
                largest = max(largest, result.ByteSize())
                u = result.uncertainty
                self.assertEqual(len(u.measurement), BANDS)
                self.assertEqual(len(u.shared), BANDS)
                self.assertEqual(len(u.combined), 0)
                with_parts += len(u.interpolation) == BANDS
        self.assertEqual(answered, 1200)
        self.assertGreater(with_parts, 0, "no answer of both parts to size")
        self.assertLess(max(sizes), CLIENT_RECEIVE_LIMIT // 2)
        self.assertLess(max(counts), MAX_UNCERTAIN_CHUNK)  # split: 512 would pass the half
        print(f"\nInterpolateBatch with uncertainty at 401 bands: chunks of {max(counts)} "
              f"results, at most {max(sizes):,} B (the largest result {largest:,} B)",
              file=sys.stderr)
        self.assertLessEqual(largest, 400 + 8 * BANDS + 3 * 4 * BANDS + 512)

    def test_appearance_renders_from_401_bands(self):
        a = self.client.appearance(self.session_id, "D65", sphere_size=32)
        image = a["D65"]
        self.assertRegex(image.hex, r"^#[0-9a-fA-F]{6}$")
        self.assertEqual(image.sphere.shape, (32, 32, 4))


if __name__ == "__main__":
    sim_path, daemon_path = live_rig.binaries()
    if not sim_path or not daemon_path:
        print("brdf-sim or brdfd is not built; skipping", file=sys.stderr)
        sys.exit(77)
    unittest.main()
