"""brdf_client's labelled structures without a daemon: readings as DataFrame / DataArray (a
synthetic session, tests/python/synthetic.py), a grid Dataset from values and a description as the
daemon writes them, per-cell provenance from the fill chain's stages, interpolation Datasets,
half/difference angles, NetCDF, progress bars, and the BrdfError subclasses."""

import contextlib
import io
import json
import os
import shutil
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, HERE)

import grpc  # noqa: E402
import xarray as xr  # noqa: E402

import synthetic  # noqa: E402
import brdf_client  # noqa: E402
from brdf_client import (BrdfError, InterpolationBatch, InterpolationResult, Vertex,  # noqa: E402
                         open_grid, write_netcdf)
from brdf_client.angles import half_diff_from_incidence, incidence_from_half_diff  # noqa: E402
from brdf_client.grid_datasets import cell_provenance, grid_dataset  # noqa: E402
from brdf_client.labels import PROVENANCE_CODE, uncertainty_name  # noqa: E402
from brdf_client.progress import Bar  # noqa: E402
from brdf_client.spectra import reading_spectrum  # noqa: E402

WL = 380.0 + 4.0 * np.arange(5)


def description(shape=(2, 3, 4, 5), fill=None, **extra):
    """A grid description as GridDescriptionJson writes it (core/export/grid/text.cc)."""
    d = {"format": "brdfd regular grid (.npy, float64, C order)",
         "axes": ["theta_i", "theta_o", "phi", "band"], "shape": list(shape),
         "theta_i_deg": {"start": 22.5, "step": 45, "count": shape[0]},
         "theta_o_deg": {"start": 15, "step": 30, "count": shape[1]},
         "phi_deg": {"start": 22.5, "step": 45, "count": shape[2]},
         "wavelength_nm": {"start": 380, "step": 4, "count": shape[3]},
         "angles": "…", "session": 3, "session_name": "paint", "quantity": "brdf",
         "unit": "sr⁻¹", "definition": "BRDF f(λ) …", "method": "octant", "mirror_phi": False,
         "reciprocity": True, "coordinates": "incidence", "trend": "none", "axis_scale": None,
         "samples": 87, "samples_left_out": 0, "cells": int(np.prod(shape[:3])),
         "filled": 0, "nan_cells": 0, "by_status": {"ok": 20, "empty_octant": 4}}
    if fill is not None:
        d["fill"] = fill
    d.update(extra)
    return d


def answer(query, spectrum, status="ok", vertices=()):
    return InterpolationResult(query=np.array(query, float), axes=("theta_i", "theta_o", "phi"),
                               status=status, method="octant", quantity="brdf", wavelengths=WL,
                               spectrum=np.array(spectrum, float), vertices=list(vertices),
                               detail="")


class Readings(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rs = synthetic.make_session()

    def test_dataframe_one_row_per_reading(self):
        df = self.rs.to_dataframe()
        self.assertEqual(len(df), len(self.rs))
        np.testing.assert_array_equal(df.index, self.rs.ids)
        np.testing.assert_array_equal(df.beta, self.rs.poses[:, 1])
        np.testing.assert_array_equal(df.phi_o, self.rs.directions[:, 3])
        self.assertEqual(list(df.columns[:3]), ["kind", "step_index", "label"])
        self.assertEqual(df.attrs["wavelength_nm"], list(self.rs.wavelengths))

    def test_dataarray_radiance_and_brdf(self):
        rad = self.rs.to_dataarray()
        np.testing.assert_array_equal(rad.values, self.rs.spectra)
        self.assertEqual(rad.attrs["units"], "W·m⁻²·sr⁻¹·nm⁻¹")
        f = self.rs.to_dataarray("brdf", white_reflectance=0.9)
        sample = int(self.rs.of_kind("sample").ids[3])
        np.testing.assert_array_equal(f.sel(reading=sample).values,
                                      reading_spectrum(self.rs, sample, "brdf", 0.9))
        self.assertEqual(set(f.kind.values), {"sample"})
        with self.assertRaises(ValueError):
            self.rs.to_dataarray("luminance")


class ReadingUncertainties(unittest.TestCase):
    """A reading's stored budget (brdf.v1.Reading.uncertainty) through ReadingSet, its DataFrame
    and its BRDF DataArray; readings without one are NaN (not estimated), never 0."""

    @staticmethod
    def reading(rid, kind, budget=None):
        r = brdf_client.brdf_pb2.Reading(id=rid, session_id="3", kind=kind)
        r.grid.start_nm, r.grid.step_nm, r.grid.count = 380, 4, 3
        r.radiance.extend([0.1, 0.2, 0.3])
        if budget is not None:
            u = r.uncertainty
            u.quantity = brdf_client.brdf_pb2.QUANTITY_BRDF
            u.value.extend([0.10, 0.11, 0.12])
            u.combined.extend(budget)
            u.independent.extend([b / 2 for b in budget])
            c = u.components.add(name="reference_signal",
                                 sharing=brdf_client.brdf_pb2.UNCERTAINTY_SHARING_REFERENCE_READING,
                                 shared_id=1)
            c.contribution.extend([-1e-4, -2e-4, -3e-4])
            u.not_estimated.append("pose: the quantity's gradient over the pose is not known")
        return r

    def setUp(self):
        pb = brdf_client.brdf_pb2
        self.rs = brdf_client.ReadingSet.from_protos([
            self.reading(1, pb.READING_KIND_REFERENCE),
            self.reading(2, pb.READING_KIND_SAMPLE, [0.002, 0.003, 0.004]),
            self.reading(3, pb.READING_KIND_SAMPLE)])

    def test_budget_and_columns(self):
        np.testing.assert_array_equal(self.rs.brdf_uncertainty[1], [0.002, 0.003, 0.004])
        np.testing.assert_array_equal(self.rs.brdf_uncertainty_independent[1],
                                      [0.001, 0.0015, 0.002])
        self.assertTrue(np.isnan(self.rs.brdf_uncertainty[0]).all())
        self.assertTrue(np.isnan(self.rs.brdf_uncertainty[2]).all())
        b = self.rs.budgets[1]
        self.assertEqual(b.quantity, "brdf")
        self.assertEqual(b.components["reference_signal"].sharing, "reference_reading")
        self.assertEqual(b.components["reference_signal"].shared_id, 1)
        np.testing.assert_array_equal(b.value, [0.10, 0.11, 0.12])
        self.assertEqual(len(b.not_estimated), 1)
        self.assertIsNone(self.rs.budgets[2])
        df = self.rs.to_dataframe()
        self.assertEqual(list(df.uncertainty_estimated), [False, True, False])
        picked = self.rs.of_kind("sample")
        np.testing.assert_array_equal(picked.brdf_uncertainty[0], [0.002, 0.003, 0.004])
        both = brdf_client.ReadingSet.concat([self.rs, picked])
        self.assertEqual(both.brdf_uncertainty.shape, (5, 3))

    def test_brdf_dataarray_carries_the_uncertainty(self):
        f = self.rs.to_dataarray("brdf")
        u = f.brdf_uncertainty.sel(reading=2).values
        np.testing.assert_array_equal(u, [0.002, 0.003, 0.004])
        self.assertTrue(np.isnan(f.brdf_uncertainty.sel(reading=3).values).all())
        self.assertEqual(f.brdf_uncertainty.attrs["units"], "sr⁻¹")
        self.assertIn("brdf_uncertainty_independent", f.coords)
        self.assertNotIn("brdf_uncertainty", self.rs.to_dataarray().coords)

    def test_integration_notes_follow_their_readings(self):
        pb = brdf_client.brdf_pb2
        halved = self.reading(4, pb.READING_KIND_SAMPLE)
        halved.integration_ms = 50
        halved.integration_note = "quality 19 (overload): integration halved from 100 to 50 ms"
        rs = brdf_client.ReadingSet.from_protos([self.reading(1, pb.READING_KIND_REFERENCE),
                                                 halved])
        self.assertEqual(list(rs.integration_notes), ["", halved.integration_note])
        self.assertEqual(list(rs.to_dataframe().integration_note), ["", halved.integration_note])
        self.assertEqual(list(rs.of_kind("sample").integration_notes), [halved.integration_note])
        both = brdf_client.ReadingSet.concat([rs, self.rs])
        self.assertEqual(list(both.integration_notes), ["", halved.integration_note, "", "", ""])
        self.assertEqual(list(synthetic.make_session().integration_notes[:2]), ["", ""])

    def test_synthetic_sets_are_not_estimated(self):
        rs = synthetic.make_session()
        self.assertEqual(rs.brdf_uncertainty.shape, rs.spectra.shape)
        self.assertTrue(np.isnan(rs.brdf_uncertainty).all())


class Grids(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="brdf_grid_offline_")
        self.addCleanup(shutil.rmtree, self.dir, True)

    def test_dataset_holds_the_values_axes_and_description(self):
        values = np.arange(2 * 3 * 4 * 5, dtype=float).reshape(2, 3, 4, 5)
        values[1, 2, 3] = np.nan
        fill = {"policy": "chain", "interpolated": 20, "fallback": 2, "model": 1, "empty": 1,
                "model_fraction": 1 / 24}
        ds = grid_dataset(values, description(fill=fill, axis_scale=[1, 2, 0.5]))
        self.assertTrue(np.array_equal(ds.brdf.values, values, equal_nan=True))
        np.testing.assert_array_equal(ds.theta_i, [22.5, 67.5])
        np.testing.assert_array_equal(ds.theta_o, [15, 45, 75])
        np.testing.assert_array_equal(ds.wavelength, WL)
        self.assertEqual(ds.brdf.attrs["units"], "sr⁻¹")
        self.assertEqual((ds.method.item(), bool(ds.reciprocity), ds.fill_policy.item()),
                         ("octant", True, "chain"))
        np.testing.assert_array_equal(ds.axis_scale, [1, 2, 0.5])
        np.testing.assert_array_equal(ds.fill_count, [20, 2, 1, 1])
        self.assertEqual(dict(zip(ds.status.values, ds.status_count.values)),
                         {"ok": 20, "empty_octant": 4})
        # no stage-by-stage grids given: the chain's cells are "unrecorded", NaN cells empty
        self.assertEqual(int((ds.provenance == PROVENANCE_CODE["unrecorded"]).sum()), 23)
        self.assertEqual(int((ds.provenance == PROVENANCE_CODE["empty"]).sum()), 1)
        self.assertIn(uncertainty_name("brdf"), ds.attrs["uncertainty"])
        with self.assertRaises(ValueError):
            grid_dataset(values[:1], description())

    def test_provenance_from_the_stages(self):
        chain = np.ones((1, 1, 4, 2))
        chain[0, 0, 3] = np.nan
        method = np.full_like(chain, np.nan)
        method[0, 0, 0] = 1
        delaunay = np.full_like(chain, np.nan)
        delaunay[0, 0, :2] = 1
        codes = cell_provenance(chain, "chain", method, delaunay)
        self.assertEqual([int(c) for c in codes.ravel()],
                         [PROVENANCE_CODE[k] for k in ("interpolated", "fallback", "model",
                                                        "empty")])
        # Delaunay as the method: no fallback stage
        codes = cell_provenance(chain, "chain", delaunay, None)
        self.assertEqual(list(codes.ravel()), [0, 0, 2, 3])
        self.assertEqual(list(cell_provenance(chain, "none").ravel()), [0, 0, 0, 3])

    def test_open_grid_reads_the_npy_and_its_sidecar(self):
        values = np.random.default_rng(3).random((2, 3, 4, 5))
        path = os.path.join(self.dir, "g.npy")
        np.save(path, values)
        with open(path + ".json", "w", encoding="utf-8") as f:
            json.dump(description(), f)
        ds = open_grid(path)
        np.testing.assert_array_equal(ds.brdf.values, values)
        self.assertEqual(ds.attrs["source"], path)
        with self.assertRaises(OSError) as caught:
            open_grid(os.path.join(self.dir, "missing.npy"))
        self.assertIn("brdfctl export", str(caught.exception))

    def test_netcdf_round_trip(self):
        ds = grid_dataset(np.ones((2, 3, 4, 5)), description())
        for engine in ("netcdf4", "scipy"):
            path = write_netcdf(ds, os.path.join(self.dir, f"{engine}.nc"), engine=engine)
            with xr.open_dataset(path, engine=engine) as back:
                np.testing.assert_array_equal(back.brdf.values, ds.brdf.values)
                self.assertEqual(back.attrs["session_name"], "paint")
                self.assertEqual(bool(back.reciprocity), True)


class Interpolations(unittest.TestCase):
    def test_batch_and_one_answer(self):
        v = [Vertex(7, np.array([1.0, 2, 3]), 0.25), Vertex(9, np.array([4.0, 5, 6]), 0.75)]
        batch = InterpolationBatch([answer([30, 40, 50], np.arange(5), vertices=v),
                                    answer([80, 80, 5], [], status="empty_octant")])
        ds = batch.to_dataset()
        self.assertEqual(ds.brdf.dims, ("direction", "wavelength"))
        self.assertTrue(np.isnan(ds.brdf.values[1]).all())
        self.assertEqual(list(ds.status.values), ["ok", "empty_octant"])
        np.testing.assert_array_equal(ds.vertex_reading_id.values, [[7, 9], [0, 0]])
        self.assertTrue(np.isnan(ds.vertex_weight.values[1]).all())
        np.testing.assert_array_equal(ds.vertex_coords.values[0, 1], [4, 5, 6])
        np.testing.assert_array_equal(ds.theta_o.values, [40, 80])
        one = batch[0].to_dataset()
        self.assertEqual(one.brdf.dims, ("wavelength",))
        self.assertEqual(float(one.phi), 50)
        failed = batch[1].to_dataset()
        self.assertTrue(np.isnan(failed.brdf.values).all())
        self.assertEqual(failed.sizes["wavelength"], 5)


class InterpolationUncertainties(unittest.TestCase):
    """InterpolationResult.uncertainty from brdf.v1.InterpolationResult (include_uncertainty),
    through InterpolationBatch's (N, m) arrays and the Datasets; answers without one are NaN
    there (not asked or not estimated), never 0."""

    @staticmethod
    def proto(with_uncertainty, interpolation=True):
        pb = brdf_client.brdf_pb2
        r = pb.InterpolationResult(status=pb.INTERPOLATION_STATUS_OK,
                                   method=pb.INTERPOLATION_METHOD_OCTANT,
                                   quantity=pb.QUANTITY_BRDF)
        r.query.iso.theta_i, r.query.iso.theta_o, r.query.iso.phi = 30, 40, 50
        r.grid.start_nm, r.grid.step_nm, r.grid.count = 380, 4, 3
        r.spectrum.extend([0.10, 0.11, 0.12])
        r.vertices.add(reading_id=7, weight=1.0).coords.extend([30, 40, 50])
        if with_uncertainty:
            u = r.uncertainty
            u.measurement.extend([0.003, 0.004, 0.005])
            u.shared.extend([0.002, 0.003, 0.004])
            if interpolation:
                u.interpolation.extend([0.004, 0.003, 0.0])
            u.combined.extend([0.005, 0.005, 0.005])
            u.not_estimated.append("reading 9: no uncertainty budget (not estimated)")
        return r

    def test_result_batch_and_dataset(self):
        # The wire's spectra are float32: the values read back are 0.003 etc. rounded to float.
        f32 = np.float32
        with_u = InterpolationResult.from_proto(self.proto(True))
        without = InterpolationResult.from_proto(self.proto(False))
        self.assertIsNone(without.uncertainty)
        u = with_u.uncertainty
        self.assertIsInstance(u, brdf_client.InterpolationUncertainty)
        np.testing.assert_array_equal(u.measurement, f32([0.003, 0.004, 0.005]))
        np.testing.assert_array_equal(u.shared, f32([0.002, 0.003, 0.004]))
        np.testing.assert_array_equal(u.interpolation, f32([0.004, 0.003, 0.0]))
        np.testing.assert_array_equal(u.combined, f32([0.005, 0.005, 0.005]))
        self.assertEqual(u.not_estimated, ["reading 9: no uncertainty budget (not estimated)"])

        nearest = InterpolationResult.from_proto(self.proto(True, interpolation=False))
        batch = InterpolationBatch([with_u, without, nearest])
        np.testing.assert_array_equal(batch.u_combined[0], f32([0.005, 0.005, 0.005]))
        self.assertTrue(np.isnan(batch.u_combined[1]).all())   # not asked: NaN, not 0
        np.testing.assert_array_equal(batch.u_measurement[2], f32([0.003, 0.004, 0.005]))
        self.assertTrue(np.isnan(batch.u_interpolation[2]).all())  # not estimated

        ds = batch.to_dataset()
        name = uncertainty_name("brdf")
        self.assertEqual(ds[name].dims, ("direction", "wavelength"))
        np.testing.assert_array_equal(ds[name].values[0], f32([0.005, 0.005, 0.005]))
        self.assertTrue(np.isnan(ds[name + "_interpolation"].values[2]).all())
        self.assertIn("k = 1", ds.attrs["uncertainty"])
        one = with_u.to_dataset()
        np.testing.assert_array_equal(one[name + "_measurement"].values,
                                      f32([0.003, 0.004, 0.005]))
        # Answers without uncertainty keep the old layout and its note.
        self.assertNotIn(name, without.to_dataset())

    def test_a_batch_answers_combined_is_computed_from_its_parts(self):
        """InterpolateBatch leaves combined out (brdf.proto): the client computes it as the
        daemon computes Interpolate's, sqrt(m² + i²) in float64 from the float32 parts, rounded
        to float32; a part not estimated counts 0."""
        f32 = np.float32
        both = self.proto(True)
        both.uncertainty.ClearField("combined")
        both.uncertainty.ClearField("shared")
        u = InterpolationResult.from_proto(both).uncertainty
        m, i = f32([0.003, 0.004, 0.005]).astype(float), f32([0.004, 0.003, 0.0]).astype(float)
        np.testing.assert_array_equal(u.combined, np.sqrt(m * m + i * i).astype(f32))
        np.testing.assert_allclose(u.combined, [0.005, 0.005, 0.005], rtol=1.2e-7)
        self.assertEqual(u.shared.shape, (0,))  # not asked for: empty, not zeros
        nearest = self.proto(True, interpolation=False)
        nearest.uncertainty.ClearField("combined")
        batch = InterpolationBatch([InterpolationResult.from_proto(nearest)])
        np.testing.assert_array_equal(batch.u_combined[0], f32([0.003, 0.004, 0.005]))
        self.assertTrue(np.isnan(batch.u_interpolation[0]).all())


class Angles(unittest.TestCase):
    def test_known_directions_and_round_trip(self):
        np.testing.assert_allclose(incidence_from_half_diff(0, 30, 0), (30, 30, 180), atol=1e-9)
        np.testing.assert_allclose(incidence_from_half_diff(30, 0, 0), (30, 30, 0), atol=1e-9)
        rng = np.random.default_rng(1)
        ti, to, p = rng.uniform(0, 85, 500), rng.uniform(0, 85, 500), rng.uniform(0, 180, 500)
        bi, bo, bp = incidence_from_half_diff(*half_diff_from_incidence(ti, to, p))
        same = np.abs(bi - ti) + np.abs(bo - to)
        swapped = np.abs(bi - to) + np.abs(bo - ti)  # reciprocity: the pair, either way round
        self.assertLess(float(np.max(np.minimum(same, swapped) + np.abs(bp - p))), 1e-6)


class ProgressAndErrors(unittest.TestCase):
    def test_bar_only_when_asked(self):
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            with Bar(True, total=4, desc="work", unit="step") as bar:
                bar.update(2)
                bar.moveto(4)
            self.assertFalse(bar.shown)  # closed on leaving
        self.assertIn("4/4", err.getvalue())
        quiet = io.StringIO()
        with contextlib.redirect_stderr(quiet):
            with Bar(False, total=4) as bar:
                bar.update(4)
        self.assertEqual(quiet.getvalue(), "")
        self.assertFalse(Bar(None).shown)  # not a terminal here, not a kernel

    def test_errors_are_the_subclass_of_their_code(self):
        e = BrdfError(grpc.StatusCode.NOT_FOUND, "session 9 does not exist", "Control.GetSession")
        self.assertIsInstance(e, brdf_client.NotFound)
        self.assertIsInstance(e, BrdfError)
        self.assertEqual((e.code_name, e.message, e.method),
                         ("NOT_FOUND", "session 9 does not exist", "Control.GetSession"))
        self.assertIs(type(BrdfError(grpc.StatusCode.INTERNAL, "x")), BrdfError)
        self.assertIsInstance(BrdfError(grpc.StatusCode.DATA_LOSS, "gap"), brdf_client.DataLoss)
        self.assertIsInstance(brdf_client.InvalidArgument(grpc.StatusCode.INVALID_ARGUMENT, "x"),
                              brdf_client.InvalidArgument)


if __name__ == "__main__":
    unittest.main()
