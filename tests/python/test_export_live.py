"""BrdfClient.export against a running brdfd driving brdf-sim (both started as processes).

setUpClass runs test_live.py's small sample-rotation plan to completion (the operator's prompts
answered on the simulator), then every test exports that session: the readings as CSV, a coarse
regular grid as .npy and CSV (with the fill chain and without), a MERL .binary, an RGL .bsdf
(byte for byte brdf-export's on the daemon's database, read by tools/check/rgl_read.py and
brdf_client.rgl), and the failures (unknown session, bad steps, a
caller that gives up) that must leave no file behind. StreamChecks replaces the daemon by a
server that sends broken streams (a gap, a wrong byte count, no report), which brdfd never does
on purpose, to see the client refuse them. Exit code 77 (ctest: skipped) when brdfd
or brdf-sim is not built.
"""

import concurrent.futures
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, HERE)

import grpc  # noqa: E402

import live_rig  # noqa: E402
from brdf_client import BrdfClient, BrdfError, brdf_pb2, names  # noqa: E402
from brdf_client._stubs import brdf_pb2_grpc  # noqa: E402
from brdf_client.export import ExportResult  # noqa: E402
from brdf_client.rgl import Material  # noqa: E402
from test_live import PLAN, PROMPT_ACTIONS  # noqa: E402

MERL_BYTES = 90 * 90 * 180 * 3 * 8 + 12
# A coarse grid keeps the test fast: 9 × 9 × 9 cell centres of 101 bands.
GRID_STEPS = {"step_theta_i": 10.0, "step_theta_o": 10.0, "step_phi": 20.0}
GRID_SHAPE = (9, 9, 9)


class Progress:
    """Records on_progress calls."""

    def __init__(self):
        self.calls = []

    def __call__(self, stage, fraction):
        self.calls.append((stage, fraction))

    @property
    def fractions(self):
        return [f for _, f in self.calls]


class GiveUp(Exception):
    """Raised by a progress callback to abandon an export."""


class LiveExport(unittest.TestCase):
    rig = None
    client = None
    session_id = None
    final = None
    readings = None
    out = None

    @classmethod
    def setUpClass(cls):
        sim, daemon = live_rig.binaries()
        cls.rig = live_rig.LiveRig(sim, daemon)
        cls.rig.start()
        cls.client = BrdfClient(cls.rig.address, cls.rig.operator_token)
        cls.out = tempfile.mkdtemp(prefix="brdf_export_", dir=cls.rig.dir)
        try:
            cls.client.wait_ready(10)
            cls.session_id = cls.client.submit_plan(PLAN, start_now=True).session_id
            cls.final = cls.client.wait(cls.session_id, on_prompt=cls._act, timeout=180,
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
        """A fresh path in a folder of this test's own, so that leftovers can be listed."""
        folder = os.path.join(self.out, self.id().rsplit(".", 1)[-1])
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
        return os.path.join(folder, name)

    def assertOnlyFile(self, path):
        """`path` is the folder's one file: no .partial (or other) file was left beside it."""
        folder = os.path.dirname(path)
        self.assertEqual(os.listdir(folder), [os.path.basename(path)])

    def assertProgress(self, progress):
        f = progress.fractions
        self.assertTrue(f, "no progress was reported")
        self.assertTrue(all(0.0 <= x <= 1.0 for x in f), f)
        self.assertTrue(all(b >= a for a, b in zip(f, f[1:])), f"fractions decrease: {f}")
        self.assertEqual(f[-1], 1.0)
        self.assertTrue(all(stage for stage, _ in progress.calls), progress.calls)

    def assertCode(self, code, fn, *args, **kwargs):
        with self.assertRaises(BrdfError) as caught:
            fn(*args, **kwargs)
        self.assertEqual(caught.exception.code, code, str(caught.exception))
        self.assertEqual(caught.exception.method, "Data.Export")
        self.assertTrue(caught.exception.message)
        return caught.exception

    # --- readings CSV -----------------------------------------------------------------------------

    def read_csv(self, path):
        """(column names, data rows) of a readings CSV ('#' lines are its documentation)."""
        with open(path, encoding="utf-8", newline="") as f:
            lines = [line for line in f if not line.startswith("#")]
        rows = list(csv.reader(lines))
        return rows[0], rows[1:]

    def test_readings_csv_radiance_has_every_reading(self):
        path = self.path("readings.csv")
        progress = Progress()
        r = self.client.export(self.session_id, "csv", path, quantity="radiance",
                               on_progress=progress)
        self.assertIsInstance(r, ExportResult)
        self.assertEqual((r.path, r.format), (path, "readings_csv"))
        self.assertEqual(r.file_name, f"session-{self.session_id}-readings-radiance.csv")
        self.assertEqual(r.bytes, os.path.getsize(path))
        self.assertOnlyFile(path)
        self.assertProgress(progress)
        header, rows = self.read_csv(path)
        self.assertEqual(header[0], "id")
        self.assertEqual(len(header), 16 + 101)
        self.assertEqual(r.rows, len(self.readings))
        self.assertEqual(len(rows), r.rows)
        np.testing.assert_array_equal([int(row[0]) for row in rows], self.readings.ids)
        self.assertIn(str(r.rows), r.summary)

    def test_readings_csv_brdf_into_a_folder(self):
        folder = os.path.dirname(self.path("unused"))
        r = self.client.export(self.session_id, "csv", folder)
        # A folder: the file takes the daemon's name; BRDF (the default) covers sample readings.
        self.assertEqual(r.path, os.path.join(folder, r.file_name))
        self.assertEqual(r.file_name, f"session-{self.session_id}-readings-brdf.csv")
        self.assertOnlyFile(r.path)
        _, rows = self.read_csv(r.path)
        self.assertEqual(len(rows), r.rows)
        self.assertEqual(r.rows + r.skipped_readings, self.final.summary.sample_readings)
        samples = self.readings.of_kind("sample")
        self.assertTrue(set(int(row[0]) for row in rows) <= set(samples.ids))

    # --- regular grid -----------------------------------------------------------------------------

    def test_grid_npy(self):
        path = self.path("grid.npy")
        progress = Progress()
        r = self.client.export(self.session_id, "grid", path, on_progress=progress,
                               chunk_bytes=64 * 1024, **GRID_STEPS)  # several data messages
        self.assertGreater(r.bytes, 3 * 64 * 1024)
        self.assertEqual(r.format, "grid_npy")
        self.assertOnlyFile(path)
        self.assertProgress(progress)
        self.assertIn("resampling", [stage for stage, _ in progress.calls])
        grid = np.load(path)
        self.assertEqual(grid.dtype, np.float64)
        self.assertEqual(grid.shape, GRID_SHAPE + (101,))
        self.assertEqual(tuple(r.shape), grid.shape)
        self.assertEqual(r.cells, int(np.prod(GRID_SHAPE)))
        unfilled = np.isnan(grid).any(axis=-1)
        self.assertTrue(np.array_equal(unfilled, np.isnan(grid).all(axis=-1)),
                        "a cell is NaN in every band or in none")
        self.assertEqual(int(unfilled.sum()), r.cells - r.filled_cells)
        self.assertEqual(r.unfilled_cells, r.cells - r.filled_cells)
        self.assertEqual(sum(r.unfilled_by_status.values()), r.unfilled_cells)
        self.assertGreater(r.filled_cells, 0)
        self.assertTrue(np.all(np.isfinite(grid[~unfilled])))
        self.assertEqual(r.description["shape"], list(grid.shape))
        self.assertEqual(r.description["nan_cells"], r.unfilled_cells)
        self.assertEqual(r.description["quantity"], "brdf")

    def test_grid_npy_as_float32(self):
        """float32=True: the same grid in half the bytes, each value the float64 grid's rounded
        to float32, and the sidecar says the dtype; other formats refuse it."""
        wide_path = self.path("wide.npy")
        wide = self.client.export(self.session_id, "grid", wide_path, **GRID_STEPS)
        a = np.load(wide_path)
        narrow_path = self.path("narrow.npy")
        narrow = self.client.export(self.session_id, "grid", narrow_path, float32=True,
                                    **GRID_STEPS)
        b = np.load(narrow_path)
        self.assertEqual(b.dtype, np.float32)
        self.assertEqual(b.shape, a.shape)
        self.assertLess(narrow.bytes, wide.bytes * 0.51)
        self.assertEqual(wide.description["dtype"], "float64")
        self.assertEqual(narrow.description["dtype"], "float32")
        self.assertTrue(np.array_equal(np.isnan(a), np.isnan(b)))
        self.assertTrue(np.array_equal(a.astype(np.float32), b, equal_nan=True))
        with self.assertRaisesRegex(ValueError, "float32"):
            self.client.export(self.session_id, "merl", self.path("x.binary"), float32=True)

    def test_grid_in_half_difference_coordinates(self):
        """The .json sidecar (ExportResult.description) records the coordinates; the values
        differ from the incidence grid's."""
        inc_path = self.path("inc.npy")  # path() empties the test's folder: one file
        incidence = self.client.export(self.session_id, "grid", inc_path, method="delaunay",
                                       **GRID_STEPS)
        a = np.load(inc_path)
        half_path = self.path("half.npy")
        half = self.client.export(self.session_id, "grid", half_path, method="delaunay",
                                  coordinates="half-diff", **GRID_STEPS)
        b = np.load(half_path)
        self.assertEqual(incidence.description["coordinates"], "incidence")
        self.assertEqual(half.description["coordinates"], "half_difference")
        both = np.isfinite(a) & np.isfinite(b)
        self.assertTrue(both.any())
        self.assertFalse(np.array_equal(a[both], b[both]))
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "csv", self.path("x.csv"), coordinates="half-diff")

    def test_grid_nodes_and_csv(self):
        nodes = self.client.export(self.session_id, "grid", self.path("nodes.npy"),
                                   grid_nodes=True, method="nearest", **GRID_STEPS)
        self.assertEqual(np.load(nodes.path).shape, (10, 10, 10, 101))
        self.assertEqual(nodes.filled_cells, nodes.cells)  # nearest fills every cell
        path = self.path("grid.csv")
        r = self.client.export(self.session_id, "grid", path, quantity="reflectance",
                               **GRID_STEPS)
        self.assertEqual((r.format, r.shape, r.description), ("grid_csv", (), None))
        self.assertOnlyFile(path)
        header, rows = self.read_csv(path)
        self.assertEqual(header[:4], ["theta_i", "theta_o", "phi", "status"])
        self.assertEqual(len(rows), r.cells)
        self.assertEqual(sum(row[3] == "ok" for row in rows), r.filled_cells)

    # --- MERL -------------------------------------------------------------------------------------

    def test_merl_binary(self):
        path = self.path("sample.binary")
        progress = Progress()
        r = self.client.export(self.session_id, "merl", path, on_progress=progress)
        self.assertEqual((r.format, r.file_name), ("merl_binary", f"session-{self.session_id}"
                                                                  ".binary"))
        self.assertEqual(os.path.getsize(path), MERL_BYTES)
        self.assertEqual(r.bytes, MERL_BYTES)
        self.assertOnlyFile(path)
        self.assertProgress(progress)
        dims = np.fromfile(path, dtype="<i4", count=3)
        np.testing.assert_array_equal(dims, [90, 90, 180])
        table = np.fromfile(path, dtype="<f8", offset=12).reshape(3, -1)
        self.assertEqual(r.cells, table.shape[1])
        missing = table[0] == -1
        self.assertTrue(np.array_equal(missing, np.all(table == -1, axis=0)))
        self.assertEqual(int(missing.sum()), r.cells - r.filled_cells)
        self.assertEqual(r.cells - r.filled_cells, r.unfilled_cells + r.below_horizon_cells)
        self.assertGreater(r.filled_cells, 0)
        self.assertTrue(np.all(table[:, ~missing] >= 0))
        # The default fill chain leaves no cell above the horizon without a value.
        self.assertEqual(r.unfilled_cells, 0)
        self.assertEqual(int(missing.sum()), r.below_horizon_cells)
        self.assertEqual(r.fill["policy"], "chain")
        self.assertEqual(r.fill["empty"], 0)
        self.assertEqual(r.fill["interpolated"] + r.fill["fallback"] + r.fill["model"],
                         r.filled_cells)

    def stored_brdf_and_u(self, folder):
        """(ids, BRDF, u) of the sample readings from the readings CSV (its u_<λ> columns)."""
        csv_path = os.path.join(folder, "brdf.csv")
        self.client.export(self.session_id, "csv", csv_path)
        header, rows = self.read_csv(csv_path)
        bands = [h for h in header if h.replace(".", "").isdigit()]
        values = [header.index(h) for h in bands]
        uncertain = [header.index(f"u_{h}") for h in bands]
        ids = np.array([int(row[0]) for row in rows])
        brdf = np.array([[float(row[i]) for i in values] for row in rows])
        u = np.array([[float(row[i]) for i in uncertain] for row in rows])
        return ids, brdf, u

    def test_grid_npy_with_uncertainty(self):
        """uncertainty=True: three more arrays of the grid's shape and dtype beside it, named in
        the sidecar; u ≥ 0 wherever there is a value, NaN where there is none."""
        path = self.path("grid.npy")
        r = self.client.export(self.session_id, "grid", path, uncertainty=True, sidecar=True,
                               float32=True, **GRID_STEPS)
        folder = os.path.dirname(path)
        self.assertEqual(sorted(os.listdir(folder)),
                         ["grid.npy", "grid.npy.json", "grid.u.npy",
                          "grid.u_interpolation.npy", "grid.u_measurement.npy"])
        self.assertEqual(sorted(r.parts), ["u", "u_interpolation", "u_measurement"])
        self.assertEqual(r.warnings, [])
        with open(path + ".json", encoding="utf-8") as f:
            sidecar = json.load(f)
        arrays = sidecar["uncertainty"]["arrays"]
        self.assertEqual(sidecar["uncertainty"]["k"], 1)
        self.assertEqual(sidecar["uncertainty"]["unit"], sidecar["unit"])
        self.assertEqual(sidecar["uncertainty"]["samples_without_budget"], 0)
        for name, saved in r.parts.items():
            self.assertEqual(arrays[name]["file"], os.path.basename(saved))
            self.assertEqual(os.path.dirname(saved), folder)
        values = np.load(path)
        u, u_m, u_i = (np.load(r.parts[k]) for k in ("u", "u_measurement", "u_interpolation"))
        for a in (u, u_m, u_i):
            self.assertEqual((a.shape, a.dtype), (values.shape, np.float32))
        finite = np.isfinite(values)
        self.assertTrue(finite.any())
        self.assertTrue(np.all(np.isnan(u[~finite])))
        # Model cells (the fill chain's: no measurement part) may say "not estimated" (NaN) farther
        # from every reading than the model's calibration reaches (sidecar: model_cells); every
        # interpolated cell with a value has its u.
        model = np.isnan(u_m) & finite
        self.assertTrue(np.all(np.isfinite(u[finite & ~model])),
                        "an interpolated cell with a value lacks its u")
        self.assertTrue(np.all(u[finite & ~model] >= 0))
        self.assertTrue(np.all(u_i[finite & ~model] >= 0))
        estimated = model & np.isfinite(u)
        self.assertTrue(np.all(u[estimated] >= 0))
        self.assertIn("not_estimated_beyond_deg", json.dumps(sidecar["uncertainty"]))
        # u = sqrt(u_measurement² + u_interpolation²), but model cells have no measurement part.
        self.assertEqual(int(model.all(axis=-1).sum()), r.fill["model"])
        np.testing.assert_allclose(u[finite & ~model], np.hypot(u_m, u_i)[finite & ~model],
                                   rtol=1e-5)
        np.testing.assert_array_equal(u[model], u_i[model])

    def test_grid_cell_on_a_reading_has_its_stored_u(self):
        """With the nearest method every cell is one reading's value: its measurement part is
        that reading's stored u (the readings CSV's u_<λ>) up to the blend's shared contributions
        held as floats (2⁻²⁴ relative, as Interpolate's; docs/uncertainty.md, "One blend"), and
        there is no interpolation term (NaN, as the sidecar says)."""
        path = self.path("nearest.npy")
        r = self.client.export(self.session_id, "grid", path, uncertainty=True,
                               method="nearest", **GRID_STEPS)
        values = np.load(path)
        u, u_m, u_i = (np.load(r.parts[k]) for k in ("u", "u_measurement", "u_interpolation"))
        self.assertIn("nearest method", r.description["uncertainty"]["nan"])
        ids, brdf, stored = self.stored_brdf_and_u(os.path.dirname(path))
        cells = values.reshape(-1, values.shape[-1])
        finite = np.all(np.isfinite(cells), axis=1)
        self.assertEqual(int(finite.sum()), r.cells)
        matched = set()
        for cell, measured in zip(cells[finite], u_m.reshape(cells.shape)[finite]):
            gap = np.max(np.abs(brdf - cell), axis=1)
            k = int(np.argmin(gap))
            self.assertLess(gap[k], 1e-9 * np.max(np.abs(cell)) + 1e-12, "no reading has it")
            np.testing.assert_allclose(measured, stored[k], rtol=2.0**-24, atol=0)
            matched.add(int(ids[k]))
        self.assertGreater(len(matched), 5)
        self.assertTrue(np.all(np.isnan(u_i)) and np.all(np.isnan(u)))

    def test_merl_with_uncertainty_has_its_summary_beside_it(self):
        path = self.path("paint.binary")
        r = self.client.export(self.session_id, "merl", path, uncertainty=True)
        self.assertEqual(os.path.getsize(path), MERL_BYTES)
        self.assertEqual(sorted(os.listdir(os.path.dirname(path))),
                         ["paint.binary", "paint.uncertainty.json"])
        with open(r.parts["uncertainty"], encoding="utf-8") as f:
            summary = json.load(f)
        self.assertEqual((summary["format"], summary["k"]), ("merl", 1))
        median = np.array(summary["relative_u"]["median"], dtype=float)
        p95 = np.array(summary["relative_u"]["p95"], dtype=float)
        white = np.array(summary["relative_white_standard"], dtype=float)
        self.assertEqual(median.shape, (101,))
        self.assertTrue(np.all(median > 0) and np.all(p95 >= median))
        # The white standard's part is shared by every cell: no cell's u is below it.
        self.assertTrue(np.all(white > 0), white)
        measured = np.array(summary["relative_u_measurement"]["median"], dtype=float)
        self.assertTrue(np.all(measured >= white * 0.999), (measured, white))
        with self.assertRaisesRegex(ValueError, "uncertainty"):
            self.client.export(self.session_id, "csv", self.path("x.csv"), uncertainty=True)

    def test_grid_fill_none_and_chain(self):
        none_path = self.path("none.npy")
        folder = os.path.dirname(none_path)
        none = self.client.export(self.session_id, "grid", none_path, fill="none", **GRID_STEPS)
        holes = np.isnan(np.load(none.path)).all(axis=-1)
        self.assertEqual(none.fill["policy"], "none")
        self.assertGreater(int(holes.sum()), 0, "this small session leaves the octant holes")
        self.assertEqual(none.fill["empty"], int(holes.sum()))
        self.assertEqual(none.description["fill"]["policy"], "none")
        chain = self.client.export(self.session_id, "grid", os.path.join(folder, "chain.npy"),
                                   **GRID_STEPS)
        grid = np.load(chain.path)
        self.assertTrue(np.all(np.isfinite(grid)))
        self.assertEqual(chain.fill["policy"], "chain")
        self.assertEqual(chain.fill["empty"], 0)
        self.assertEqual(chain.fill["fallback"] + chain.fill["model"], none.fill["empty"])
        np.testing.assert_array_equal(grid[~holes], np.load(none.path)[~holes])

    def test_rgl_is_brdf_exports_file_and_has_no_holes(self):
        path = self.path("sample.bsdf")
        progress = Progress()
        r = self.client.export(self.session_id, "rgl", path, rgl_theta_i_count=6,
                               rgl_resolution=16, on_progress=progress)
        self.assertEqual((r.format, r.file_name), ("rgl_bsdf", f"session-{self.session_id}.bsdf"))
        self.assertOnlyFile(path)
        self.assertProgress(progress)
        self.assertEqual(r.cells, 6 * 16 * 16)
        self.assertEqual(r.unfilled_cells, 0)
        self.assertEqual(r.fill["policy"], "chain")
        self.assertEqual(r.fill["empty"], 0)
        # brdf-export on the daemon's database, same session and options (reciprocity is on for
        # both by default): the same bytes.
        tool = os.path.join(live_rig.build_dir(), "tools", "brdf-export", "brdf-export")
        theirs = os.path.join(os.path.dirname(path), "tool.bsdf")
        subprocess.run([tool, "--db", os.path.join(self.rig.dir, "brdfd.db"), "--session",
                        str(self.session_id), "--quiet", "rgl", "--theta-i", "6",
                        "--resolution", "16", "-o", theirs], check=True, capture_output=True)
        with open(path, "rb") as a, open(theirs, "rb") as b:
            self.assertTrue(a.read() == b.read(), "the daemon's .bsdf differs from brdf-export's")
        # tools/check/rgl_read.py reads it (fields, and f at a direction) ...
        check = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "check", "rgl_read.py"),
                                path, "--at", "20,0,20,180"], capture_output=True, text=True)
        self.assertEqual(check.returncode, 0, check.stderr)
        self.assertIn("spectra: float32", check.stdout)
        # ... and the Python reader finds a value at every direction above the surface.
        m = Material(path)
        rng = np.random.default_rng(3)
        d = np.radians
        n = 300
        f = m.brdf(d(rng.uniform(0, 40, n)), d(rng.uniform(0, 360, n)),
                   d(rng.uniform(0, 40, n)), d(rng.uniform(0, 360, n)))
        self.assertTrue(np.all(np.isfinite(f)))
        self.assertTrue(np.all(f.mean(axis=1) > 0), "a direction without a value")

    # --- BiRD universal BRDF JSON ---------------------------------------------------------------------

    def test_bird_json_meets_the_formats_requirements_with_every_budget(self):
        import jsonschema  # Debian's python3-jsonschema (deploy/install-deps.sh)
        path = self.path("sample-bird.json")
        progress = Progress()
        r = self.client.export(self.session_id, "bird", path, on_progress=progress)
        self.assertEqual((r.format, r.file_name),
                         ("bird_json", f"session-{self.session_id}-bird.json"))
        self.assertOnlyFile(path)
        self.assertProgress(progress)
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        with open(os.path.join(HERE, "bird_required.schema.json"), encoding="utf-8") as f:
            schema = json.load(f)
        errors = [f"{'/'.join(map(str, e.absolute_path))}: {e.message[:200]}"
                  for e in jsonschema.Draft202012Validator(schema).iter_errors(doc)]
        self.assertEqual(errors, [])
        # One point per sample reading and band, every array as long, uBRDF written (every
        # reading of this session has a budget) and equal to the budgets' u_c.
        samples = self.readings.of_kind("sample")
        n, m = len(samples), len(samples.wavelengths)
        self.assertGreater(n, 0)
        self.assertEqual(r.rows, n * m)
        self.assertEqual(r.skipped_readings, 0)
        self.assertEqual(r.warnings, [])
        data = doc["data"]
        for column in ("theta_i", "phi_i", "theta_r", "phi_r", "wavelength_r", "BRDF", "uBRDF"):
            self.assertEqual(len(data[column]["values"]), n * m, column)
        ids = np.array(data["adhoc_variables"]["reading_id"]["values"]).reshape(n, m)
        np.testing.assert_array_equal(ids[:, 0], samples.ids)
        self.assertTrue(np.all(ids == ids[:, :1]))
        np.testing.assert_array_equal(np.array(data["wavelength_r"]["values"]).reshape(n, m),
                                      np.tile(samples.wavelengths, (n, 1)))
        u = np.array(data["uBRDF"]["values"]).reshape(n, m)
        np.testing.assert_allclose(u, samples.brdf_uncertainty, rtol=1e-12, atol=0)
        theta = np.array(data["theta_r"]["values"]).reshape(n, m)[:, 0]
        np.testing.assert_allclose(theta, samples.directions[:, 2], atol=1e-9)
        phi = np.array(data["phi_i"]["values"]).reshape(n, m)[:, 0]
        np.testing.assert_allclose(phi, np.mod(samples.directions[:, 1], 360.0), atol=1e-9)
        # The BRDF is the readings CSV's, point for point (negatives written as 0).
        csv_path = os.path.join(os.path.dirname(path), "brdf.csv")
        self.client.export(self.session_id, "csv", csv_path)
        header, rows = self.read_csv(csv_path)
        # The CSV's spectrum columns are headed by the wavelength, its uncertainties by u_<λ>.
        values = [i for i, h in enumerate(header) if h.replace(".", "").isdigit()]
        uncertain = [header.index(f"u_{header[i]}") for i in values]
        self.assertEqual([float(header[i]) for i in values], list(samples.wavelengths))
        brdf = np.array([[float(row[i]) for i in values] for row in rows])
        np.testing.assert_allclose(np.array(data["BRDF"]["values"]).reshape(n, m),
                                   np.maximum(brdf, 0.0), rtol=1e-12, atol=0)
        np.testing.assert_allclose(u, np.array([[float(row[i]) for i in uncertain]
                                                for row in rows]), rtol=1e-12, atol=0)
        # Provenance as recorded.
        meta = doc["metadata"]
        brdfd = meta["adhoc_section"]["brdfd"]
        self.assertEqual(meta["software"]["name"], "brdfd")
        self.assertRegex(meta["software"]["version"], r"^\d+\.\d+\.\d+$")
        self.assertEqual(brdfd["session_id"], int(self.session_id))
        self.assertEqual(brdfd["plan_name"], PLAN["name"])
        self.assertEqual(brdfd["readings_with_budget"], n)
        self.assertTrue(brdfd["meter_serial"] and brdfd["meter_serial"] != "not recorded by brdfd")
        self.assertNotEqual(brdfd["meter_model"], "not recorded by brdfd")  # the devices table
        self.assertEqual(meta["instrumentation"]["detection_system"]["model"],
                         brdfd["meter_model"])
        self.assertEqual(meta["sample"]["comments"],
                         "id not recorded by brdfd; " + PLAN["sampleDescription"])
        self.assertGreater(brdfd["white_standard"]["standard_uncertainty"], 0)
        self.assertTrue(meta["id"].startswith("urn:uuid:"), meta["id"])
        # The BiRD project's own schema, when its files are at hand (they are not part of the
        # repository; docs/bird-format.md, "Checking a file").
        public = os.environ.get("BIRD_SCHEMA_DIR")
        if public:
            check = subprocess.run(
                [sys.executable, os.path.join(ROOT, "tools", "check", "bird_validate.py"), public,
                 path], capture_output=True, text=True)
            self.assertEqual(check.returncode, 0, check.stdout + check.stderr)

    def test_bird_json_leaves_ubrdf_out_when_a_reading_has_no_budget(self):
        # A reading as one recorded before budgets were stored: its budget row taken out of the
        # daemon's database for this test, and put back after.
        import sqlite3
        samples = self.readings.of_kind("sample")
        reading_id = int(samples.ids[len(samples) // 2])
        db = sqlite3.connect(os.path.join(self.rig.dir, "brdfd.db"), timeout=10)
        try:
            row = db.execute("SELECT * FROM reading_uncertainty WHERE reading_id = ?",
                             (reading_id,)).fetchone()
            self.assertIsNotNone(row)
            with db:
                db.execute("DELETE FROM reading_uncertainty WHERE reading_id = ?", (reading_id,))
            path = self.path("no-budget-bird.json")
            r = self.client.export(self.session_id, "bird", path)
        finally:
            with db:
                db.execute(f"INSERT OR IGNORE INTO reading_uncertainty VALUES "
                           f"({','.join('?' * len(row))})", row)
            db.close()
        n, m = len(samples), len(samples.wavelengths)
        self.assertEqual(r.rows, n * m)
        self.assertEqual(len(r.warnings), 1, r.warnings)
        self.assertIn(f"uBRDF is left out: 1 of the {n} written readings", r.warnings[0])
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        self.assertNotIn("uBRDF", doc["data"])
        self.assertEqual(len(doc["data"]["BRDF"]["values"]), n * m)
        self.assertIn("uBRDF is left out: 1 of the", doc["metadata"]["comments"])
        self.assertEqual(doc["metadata"]["adhoc_section"]["brdfd"]["readings_with_budget"], n - 1)

    def test_bird_json_is_always_the_brdf(self):
        path = self.path("reflectance-bird.json")
        e = self.assertCode(grpc.StatusCode.INVALID_ARGUMENT, self.client.export,
                            self.session_id, "bird", path, quantity="reflectance")
        self.assertIn("quantity", e.message)
        self.assertEqual(os.listdir(os.path.dirname(path)), [])

    # --- failures leave no file -------------------------------------------------------------------

    def test_unknown_session_is_not_found_and_leaves_nothing(self):
        path = self.path("missing.csv")
        e = self.assertCode(grpc.StatusCode.NOT_FOUND, self.client.export, "999999", "csv", path)
        self.assertIn("999999", e.message)
        self.assertEqual(os.listdir(os.path.dirname(path)), [])

    def test_bad_step_is_invalid_argument_and_leaves_nothing(self):
        path = self.path("bad.npy")
        e = self.assertCode(grpc.StatusCode.INVALID_ARGUMENT, self.client.export,
                            self.session_id, "grid", path, step_theta_i=7.0)
        self.assertIn("7", e.message)
        self.assertEqual(os.listdir(os.path.dirname(path)), [])

    def test_caller_giving_up_removes_the_partial_file(self):
        path = self.path("abandoned.npy")
        written = []

        def give_up(stage, _fraction):
            if stage == "done":  # every byte is in the .partial file by now
                written.append(os.path.getsize(path + ".partial"))
                raise GiveUp()

        with self.assertRaises(GiveUp):
            self.client.export(self.session_id, "grid", path, on_progress=give_up, **GRID_STEPS)
        self.assertTrue(written and written[0] > 0, written)
        self.assertEqual(os.listdir(os.path.dirname(path)), [])
        # A deadline that passes mid-export: the daemon's code, no file.
        self.assertCode(grpc.StatusCode.DEADLINE_EXCEEDED, self.client.export, self.session_id,
                        "merl", path, timeout=0.001)
        self.assertEqual(os.listdir(os.path.dirname(path)), [])

    def test_arguments_checked_before_calling(self):
        path = self.path("never.csv")
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "csv", path, step_phi=10.0)
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "tiff", path)
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "grid", path, method="cubic")
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "grid", path, rgb=True)
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "merl", path, fill="holes")
        with self.assertRaises(ValueError):
            self.client.export(self.session_id, "csv", path, fill="none")
        self.assertEqual(os.listdir(os.path.dirname(path)), [])


class ScriptedData(brdf_pb2_grpc.DataServicer):
    """A Data service whose Export sends the chunks it is given, then fails with `abort` if set."""

    def __init__(self):
        self.chunks = []
        self.abort = None

    def Export(self, request, context):  # noqa: N802 (the gRPC method's name)
        yield from self.chunks
        if self.abort:
            context.abort(*self.abort)


def data(offset, content):
    return brdf_pb2.ExportChunk(data=brdf_pb2.ExportData(offset=offset, content=content))


def report(nbytes):
    return brdf_pb2.ExportChunk(report=brdf_pb2.ExportReport(file_name="x.csv", bytes=nbytes,
                                                             summary="2 rows", rows=2))


class StreamChecks(unittest.TestCase):
    """The client's checks of the stream itself, against a server that breaks the protocol."""

    @classmethod
    def setUpClass(cls):
        cls.service = ScriptedData()
        cls.server = grpc.server(concurrent.futures.ThreadPoolExecutor(max_workers=2))
        brdf_pb2_grpc.add_DataServicer_to_server(cls.service, cls.server)
        port = cls.server.add_insecure_port("127.0.0.1:0")
        cls.server.start()
        cls.client = BrdfClient(f"127.0.0.1:{port}", "")
        cls.dir = tempfile.mkdtemp(prefix="brdf_export_stream_")

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.stop(None)
        shutil.rmtree(cls.dir, ignore_errors=True)

    def export(self, chunks, abort=None):
        self.service.chunks, self.service.abort = chunks, abort
        for name in os.listdir(self.dir):
            os.remove(os.path.join(self.dir, name))
        return self.client.export("1", "csv", os.path.join(self.dir, "x.csv"), timeout=30)

    def assertRefused(self, chunks, code, words, abort=None):
        with self.assertRaises(BrdfError) as caught:
            self.export(chunks, abort)
        self.assertEqual(caught.exception.code, code, str(caught.exception))
        self.assertIn(words, caught.exception.message)
        self.assertEqual(os.listdir(self.dir), [])

    def test_a_whole_stream_is_saved(self):
        r = self.export([data(0, b"ab\n"), data(3, b"cd\n"), report(6)])
        with open(r.path, "rb") as f:
            self.assertEqual(f.read(), b"ab\ncd\n")
        self.assertEqual((r.bytes, r.rows, r.file_name), (6, 2, "x.csv"))
        self.assertEqual(os.listdir(self.dir), ["x.csv"])

    def test_a_gap_is_data_loss(self):
        self.assertRefused([data(0, b"ab\n"), data(4, b"cd\n"), report(7)],
                           grpc.StatusCode.DATA_LOSS, "offset 4 after 3 bytes")

    def test_a_wrong_byte_count_is_data_loss(self):
        self.assertRefused([data(0, b"ab\n"), report(4)], grpc.StatusCode.DATA_LOSS,
                           "counts 4 bytes but 3 came")

    def test_no_report_is_data_loss(self):
        self.assertRefused([data(0, b"ab\n")], grpc.StatusCode.DATA_LOSS, "without a report")

    def test_a_failure_after_some_bytes_keeps_the_servers_code_and_message(self):
        self.assertRefused([data(0, b"ab\n")], grpc.StatusCode.FAILED_PRECONDITION,
                           "no usable readings",
                           abort=(grpc.StatusCode.FAILED_PRECONDITION, "no usable readings"))


if __name__ == "__main__":
    sim_path, daemon_path = live_rig.binaries()
    if not sim_path or not daemon_path:
        print(f"skipped: brdf-sim or brdfd is not built in {live_rig.build_dir()} "
              f"(brdf-sim: {sim_path}, brdfd: {daemon_path})")
        sys.exit(77)
    unittest.main()
