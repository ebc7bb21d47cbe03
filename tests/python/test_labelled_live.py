"""brdf_client's labelled data against brdf-sim + brdfd, on the quick start's session (the demo
plan, examples/plans/demo.json, run to completion with its prompts answered on the simulator).

The labelled structures must be the daemon's numbers with their labels, nothing recomputed: the
readings' DataFrame and DataArray against the ReadingSet; the grid Dataset against the raw .npy
and its .json sidecar, cell for cell, with each cell's provenance checked against exports with
fill "none"; interpolation Datasets against the batch they come from; NetCDF round trips. Also:
progress bars, Ctrl-C cancelling an export, errors as exceptions with the daemon's code and
message, watch as an iterator.
Exit code 77 (ctest: skipped) when brdfd or brdf-sim is not built.
"""

import contextlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, HERE)

import xarray as xr  # noqa: E402

import live_rig  # noqa: E402
import brdf_client  # noqa: E402
from brdf_client import BrdfClient, BrdfError, names, open_grid, write_netcdf  # noqa: E402
from brdf_client.labels import PROVENANCE_CODE  # noqa: E402
from brdf_client.spectra import reading_spectrum  # noqa: E402

DEMO = os.path.join(ROOT, "examples", "plans", "demo.json")
STEP = 10  # 9 × 9 × 18 cells: quick, and every stage of the fill chain has cells


class Labelled(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sim, daemon = live_rig.binaries()
        cls.rig = live_rig.LiveRig(sim, daemon)
        cls.rig.start()
        try:
            cls.session_id = live_rig.run_demo(cls.rig)
        except Exception:
            print(cls.rig.log("brdfd"), file=sys.stderr)
            cls.rig.stop()
            raise
        cls.client = BrdfClient(cls.rig.address, token=cls.rig.analyst_token)
        cls.readings = cls.client.load_readings(cls.session_id, progress=False)
        cls.dir = tempfile.mkdtemp(prefix="brdf_labelled_", dir=os.environ.get(
            "BRDF_TEST_OUTPUT_DIR"))

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.rig.stop()
        cls.rig.cleanup()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, f"{self.id().rsplit('.', 1)[-1]}-{name}")

    # --- readings ----------------------------------------------------------------------------

    def test_readings_as_a_dataframe_one_row_each(self):
        rs = self.readings
        df = rs.to_dataframe()
        self.assertEqual(len(df), len(rs))
        self.assertEqual(df.index.name, "reading_id")
        np.testing.assert_array_equal(df.index.to_numpy(), rs.ids)
        self.assertEqual(list(df.kind), list(rs.kinds))
        for k, column in enumerate(("alpha", "beta", "gamma", "delta")):
            np.testing.assert_array_equal(df[column].to_numpy(), rs.poses[:, k])
        for k, column in enumerate(("theta_i", "phi_i", "theta_o", "phi_o")):
            np.testing.assert_array_equal(df[column].to_numpy(), rs.directions[:, k])
        np.testing.assert_array_equal(df["phi"].to_numpy(), rs.iso[:, 2])
        np.testing.assert_array_equal(df["quality"].to_numpy(), rs.quality)
        np.testing.assert_array_equal(df["flagged"].to_numpy(), rs.flagged)
        np.testing.assert_array_equal(df["reference_id"].to_numpy(), rs.reference_ids)
        np.testing.assert_array_equal(df["dark_id"].to_numpy(), rs.dark_ids)
        self.assertEqual(set(df.kind), {"sample", "reference", "dark"})
        self.assertEqual(df.attrs["units"]["theta_i"], "degree")

    def test_spectra_as_a_dataarray_reading_by_wavelength(self):
        rs = self.readings
        rad = rs.to_dataarray()
        self.assertEqual(rad.dims, ("reading", "wavelength"))
        np.testing.assert_array_equal(rad.values, rs.spectra)
        np.testing.assert_array_equal(rad.reading.values, rs.ids)
        np.testing.assert_array_equal(rad.wavelength.values, rs.wavelengths)
        self.assertEqual(rad.wavelength.attrs["units"], "nm")
        self.assertEqual(rad.attrs["units"], names.QUANTITY_UNITS["radiance"])
        f = rs.to_dataarray("brdf")
        samples = rs.of_kind("sample")
        np.testing.assert_array_equal(f.reading.values, samples.ids)
        self.assertTrue(set(f.kind.values) == {"sample"})
        some = int(samples.ids[len(samples) // 2])
        np.testing.assert_array_equal(f.sel(reading=some).values,
                                      reading_spectrum(rs, some, "brdf", 0.99))
        # Figure 8's check from the labelled data: the daemon's answer is the weighted sum of its
        # vertices' BRDF spectra.
        r = self.client.interpolate(self.session_id, 35, 40, 40).to_dataset()
        self.assertEqual(str(r.status.values), "ok")
        blend = (f.sel(reading=r.vertex_reading_id) * r.vertex_weight).sum("vertex")
        np.testing.assert_allclose(blend.values, r.brdf.values, rtol=1e-9)

    # --- grids -------------------------------------------------------------------------------

    def test_grid_is_the_npy_and_its_sidecar_cell_for_cell(self):
        path = self.path("grid.npy")
        ds = self.client.grid(self.session_id, step=STEP, path=path, progress=False)
        raw = np.load(path)
        with open(path + ".json", encoding="utf-8") as f:
            side = json.load(f)
        self.assertTrue(np.array_equal(ds.brdf.values, raw, equal_nan=True))
        self.assertEqual(list(ds.brdf.dims), ["theta_i", "theta_o", "phi", "wavelength"])
        for dim, key in (("theta_i", "theta_i_deg"), ("theta_o", "theta_o_deg"),
                         ("phi", "phi_deg"), ("wavelength", "wavelength_nm")):
            a = side[key]
            np.testing.assert_array_equal(ds[dim].values,
                                          a["start"] + a["step"] * np.arange(a["count"]))
        self.assertEqual(ds.brdf.attrs["units"], side["unit"])
        self.assertEqual(ds.brdf.attrs["quantity"], side["quantity"])
        self.assertEqual((ds.attrs["unit"], ds.attrs["session"]), (side["unit"], side["session"]))
        for key in ("method", "coordinates", "trend", "mirror_phi", "reciprocity"):
            self.assertEqual(ds[key].item(), side[key], key)
        self.assertEqual(ds.fill_policy.item(), side["fill"]["policy"])
        for source in ("interpolated", "fallback", "model", "empty"):
            self.assertEqual(int(ds.fill_count.sel(fill_source=source)), side["fill"][source])
            # per-cell provenance adds up to the sidecar's counts
            self.assertEqual(int((ds.provenance == PROVENANCE_CODE[source]).sum()),
                             side["fill"][source], source)
        self.assertGreater(side["fill"]["model"], 0, "the demo session should need the model")
        self.assertEqual(json.loads(ds.attrs["sidecar"]), side)
        for key in ("cells", "filled", "nan_cells", "samples"):
            self.assertEqual(ds.attrs[key], side[key])
        # open_grid reads the same pair into the same numbers
        again = open_grid(path)
        self.assertTrue(np.array_equal(again.brdf.values, raw, equal_nan=True))
        self.assertEqual(again.attrs["sidecar"], ds.attrs["sidecar"])

    def test_provenance_agrees_with_the_chains_stages_exported_alone(self):
        ds = self.client.grid(self.session_id, step=STEP, progress=False)
        alone = {}
        for method in ("octant", "delaunay"):
            p = self.path(f"{method}.npy")
            self.client.export(self.session_id, "grid", p, method=method, fill="none",
                               step_theta_i=STEP, step_theta_o=STEP, step_phi=STEP)
            alone[method] = np.load(p)
        prov = ds.provenance.values
        for code, values in ((PROVENANCE_CODE["interpolated"], alone["octant"]),
                             (PROVENANCE_CODE["fallback"], alone["delaunay"])):
            cells = prov == code
            self.assertTrue(cells.any())
            np.testing.assert_array_equal(ds.brdf.values[cells], values[cells])
        model = prov == PROVENANCE_CODE["model"]
        self.assertTrue(np.isnan(alone["delaunay"][model]).all())
        self.assertTrue(np.isfinite(ds.brdf.values[model]).all())

    def test_grid_with_fill_none_has_nan_where_empty(self):
        ds = self.client.grid(self.session_id, step=STEP, fill="none", progress=False)
        empty = ds.provenance.values == PROVENANCE_CODE["empty"]
        self.assertTrue(empty.any())
        self.assertTrue(np.isnan(ds.brdf.values[empty]).all())
        self.assertTrue(np.isfinite(ds.brdf.values[~empty]).all())
        self.assertEqual(int(empty.sum()), ds.attrs["nan_cells"])
        self.assertEqual(ds.fill_policy.item(), "none")

    def test_netcdf_round_trip_both_engines(self):
        ds = self.client.grid(self.session_id, step=STEP, progress=False,
                              netcdf=self.path("grid.nc"))
        for engine, path in (("netcdf4", self.path("grid.nc")), ("scipy", self.path("g3.nc"))):
            if engine == "scipy":
                write_netcdf(ds, path, engine="scipy")
            with xr.open_dataset(path, engine=engine) as back:
                self.assertTrue(np.array_equal(back.brdf.values, ds.brdf.values, equal_nan=True))
                np.testing.assert_array_equal(back.provenance.values, ds.provenance.values)
                self.assertEqual(back.brdf.attrs["units"], "sr⁻¹")
                self.assertEqual(str(back.method.values), "octant")
                self.assertEqual(back.attrs["sidecar"], ds.attrs["sidecar"])
        spectra = self.readings.to_dataarray("brdf")
        with xr.open_dataset(write_netcdf(spectra, self.path("spectra.nc"))) as back:
            np.testing.assert_array_equal(back.brdf.values, spectra.values)
            self.assertEqual(list(back.kind.values), list(spectra.kind.values))

    # --- interpolations ----------------------------------------------------------------------

    def test_batch_as_a_dataset(self):
        dirs = [[35, 40, 40], [20, 20, 90], [89, 89, 5]]
        batch = self.client.interpolate_batch(self.session_id, dirs, method="delaunay",
                                              progress=False)
        ds = batch.to_dataset()
        self.assertEqual(ds.brdf.dims, ("direction", "wavelength"))
        self.assertTrue(np.array_equal(ds.brdf.values, batch.spectra, equal_nan=True))
        self.assertEqual(list(ds.status.values), list(batch.statuses))
        np.testing.assert_array_equal(ds.theta_i.values, [35, 20, 89])
        for i, r in enumerate(batch):
            k = len(r.vertices)
            np.testing.assert_array_equal(ds.vertex_reading_id.values[i, :k], r.vertex_ids)
            np.testing.assert_array_equal(ds.vertex_weight.values[i, :k], r.weights)
        self.assertEqual(ds.attrs["method"], "delaunay")

    def test_interpolated_grid_in_both_coordinate_systems(self):
        ti, to, phi = [20.0, 40.0], [10.0, 30.0, 50.0], [0.0, 90.0, 180.0]
        g = self.client.interpolate_grid(self.session_id, theta_i=ti, theta_o=to, phi=phi,
                                         method="delaunay", progress=False)
        dirs = np.array([[a, b, c] for a in ti for b in to for c in phi])
        batch = self.client.interpolate_batch(self.session_id, dirs, method="delaunay")
        self.assertTrue(np.array_equal(g.brdf.values.reshape(len(dirs), -1), batch.spectra,
                                       equal_nan=True))
        self.assertEqual(g.brdf.dims, ("theta_i", "theta_o", "phi", "wavelength"))
        h = self.client.interpolate_grid(self.session_id, theta_h=[0, 20, 40, 80],
                                         theta_d=[10, 30, 60], phi_d=[0, 90],
                                         method="delaunay", progress=False)
        self.assertEqual(h.brdf.dims, ("theta_h", "theta_d", "phi_d", "wavelength"))
        np.testing.assert_allclose(h.theta_i.sel(theta_h=0, theta_d=30, phi_d=0), 30)
        np.testing.assert_allclose(h.phi.sel(theta_h=0, theta_d=30, phi_d=0), 180)
        below = h.status.values == "below_horizon"
        self.assertTrue(below.any())  # θh 80°, θd 60°
        self.assertTrue(np.isnan(h.brdf.values[below]).all())
        ok = h.status.values == "ok"
        self.assertTrue(ok.any())
        self.assertTrue((h.provenance.values[ok] == PROVENANCE_CODE["interpolated"]).all())
        with self.assertRaises(ValueError):
            self.client.interpolate_grid(self.session_id, theta_i=[10], theta_d=[5], phi=[0])

    # --- progress, cancelling, errors, watch -------------------------------------------------

    def test_progress_bars_on_request(self):
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            self.client.interpolate_batch(self.session_id, [[35, 40, 40]] * 50, progress=True)
            self.client.load_readings(self.session_id, progress=True)
            self.client.export(self.session_id, "csv", self.path("r.csv"), progress=True)
        text = err.getvalue()
        self.assertIn("interpolating (octant)", text)
        self.assertIn("50/50", text)
        self.assertIn(f"{len(self.readings)}reading", text.replace(" ", ""))
        self.assertIn("100%", text)
        quiet = io.StringIO()
        with contextlib.redirect_stderr(quiet):
            self.client.interpolate_batch(self.session_id, [[35, 40, 40]], progress=False)
        self.assertEqual(quiet.getvalue(), "")

    def test_ctrl_c_cancels_an_export_and_leaves_no_file(self):
        target = self.path("big.npy")
        script = textwrap.dedent(f"""
            import os, signal, sys
            # As at a terminal: Ctrl-C raises KeyboardInterrupt (a shell's background job, as
            # ctest may be, starts with SIGINT ignored).
            signal.signal(signal.SIGINT, signal.default_int_handler)
            sys.path.insert(0, {os.path.join(ROOT, 'clients', 'python')!r})
            from brdf_client import BrdfClient
            def show(stage, fraction):
                print("progress", stage, flush=True)
            brdf = BrdfClient({self.rig.address!r}, token={self.rig.analyst_token!r})
            brdf.export({self.session_id!r}, "grid", {target!r}, step_theta_i=1,
                        step_theta_o=1, step_phi=1, on_progress=show, progress=True)
            print("finished", flush=True)
        """)
        proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        try:
            first = proc.stdout.readline()
            if not first.startswith("progress"):
                self.fail(f"the export did not start: {first}{proc.communicate()[1]}")
            proc.send_signal(signal.SIGINT)  # Ctrl-C
            out, err = proc.communicate(timeout=60)
        finally:
            if proc.poll() is None:
                proc.kill()
            finished = os.path.exists(target)
            for leftover in (target, target + ".partial"):
                if os.path.exists(leftover):
                    os.remove(leftover)  # 1.2 GB: never left behind, even when this fails
        self.assertFalse(finished, f"the export ran to its end despite Ctrl-C: {err[-2000:]}")
        self.assertNotIn("finished", out)
        self.assertIn("KeyboardInterrupt", err)
        self.assertFalse(os.path.exists(target))
        self.assertFalse(os.path.exists(target + ".partial"))
        # the daemon is fine and answers the next call at once
        started = time.monotonic()
        self.assertEqual(self.client.get_session(self.session_id).session_id, self.session_id)
        self.assertLess(time.monotonic() - started, 5)

    def test_errors_are_exceptions_with_the_daemons_code_and_message(self):
        with self.assertRaises(brdf_client.NotFound) as caught:
            self.client.get_session("999999")
        e = caught.exception
        self.assertIsInstance(e, BrdfError)
        self.assertEqual(e.code_name, "NOT_FOUND")
        self.assertIn("999999", e.message)
        with self.assertRaises(brdf_client.InvalidArgument) as caught:
            self.client.grid(self.session_id, step=7, progress=False)
        self.assertEqual(caught.exception.code_name, "INVALID_ARGUMENT")
        self.assertTrue(caught.exception.message)
        with self.assertRaises(brdf_client.PermissionDenied):
            self.client.submit_plan(DEMO)  # an analyst token only reads

    def test_watch_is_an_iterator_of_events(self):
        events = self.client.watch(self.session_id)
        first = next(events)
        self.assertEqual(first.kind, "snapshot")
        self.assertEqual(names.state_name(first.data.state), "completed")
        self.assertEqual(list(events), [])  # a completed session's stream ends after it
        events.close()


if __name__ == "__main__":
    if None in live_rig.binaries():
        print("brdfd or brdf-sim is not built: skipped", file=sys.stderr)
        sys.exit(77)
    unittest.main()
