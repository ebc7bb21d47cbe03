"""brdf_client without a daemon: stub generation, the conversions between the API's messages and
NumPy, plans, errors, the BRDF of stored readings, and the figures drawn from a synthetic session
(tests/python/synthetic.py)."""

import glob
import os
import pathlib
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

import synthetic  # noqa: E402
from brdf_client import (BrdfClient, BrdfError, InterpolationBatch, InterpolationResult,  # noqa: E402
                         ReadingSet, brdf_pb2, names, plan_pb2, to_plan)
from brdf_client.figures import _common, fig7, fig8, polar  # noqa: E402
from brdf_client.figures.__main__ import describe  # noqa: E402
from brdf_client.spectra import reading_spectrum, vertex_spectra  # noqa: E402

SCRIPT = os.path.join(ROOT, "clients", "python", "generate_stubs.sh")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def output_dir(name):
    base = os.environ.get("BRDF_TEST_OUTPUT_DIR") or tempfile.mkdtemp(prefix="brdf_pyclient_")
    path = os.path.join(base, name)
    os.makedirs(path, exist_ok=True)
    return path


class Stubs(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="brdf_stubs_")
        self.addCleanup(shutil.rmtree, self.dir, True)

    def generate(self, out, proto_root=None):
        env = dict(os.environ, BRDF_PROTO_ROOT=proto_root or os.path.join(ROOT, "proto"))
        return subprocess.run(["bash", SCRIPT, out], env=env, capture_output=True, text=True,
                              check=False, timeout=60)

    def test_generates_once_and_again_when_a_proto_changes(self):
        protos = os.path.join(self.dir, "proto")
        shutil.copytree(os.path.join(ROOT, "proto"), protos)
        out = os.path.join(self.dir, "stubs")
        first = self.generate(out, protos)
        self.assertEqual(first.returncode, 0, first.stderr)
        files = sorted(glob.glob(os.path.join(out, "brdf", "v1", "*.py")))
        self.assertEqual([os.path.basename(f) for f in files],
                         ["brdf_pb2.py", "brdf_pb2_grpc.py", "plan_pb2.py", "plan_pb2_grpc.py"])
        stamp = pathlib.Path(out, ".stamp").read_text(encoding="utf-8")
        mtimes = [os.stat(f).st_mtime_ns for f in files]

        second = self.generate(out, protos)  # unchanged: nothing happens
        self.assertEqual(second.returncode, 0, second.stderr)
        self.assertEqual(second.stderr, "")
        self.assertEqual([os.stat(f).st_mtime_ns for f in files], mtimes)

        with open(os.path.join(protos, "brdf", "v1", "plan.proto"), "a", encoding="utf-8") as f:
            f.write("\n// a comment changes the file, so the stubs are made again\n")
        third = self.generate(out, protos)
        self.assertEqual(third.returncode, 0, third.stderr)
        self.assertIn("wrote", third.stderr)
        self.assertNotEqual(pathlib.Path(out, ".stamp").read_text(encoding="utf-8"), stamp)

    def test_missing_protos_fail_with_a_hint(self):
        done = self.generate(os.path.join(self.dir, "stubs"), os.path.join(self.dir, "nowhere"))
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("BRDF_PROTO_ROOT", done.stderr)

    def test_runtime_reads_what_protoc_wrote(self):
        session = brdf_pb2.Session(session_id="7", name="x", state=brdf_pb2.SESSION_STATE_PAUSED)
        session.plan.sample_rotation.alpha.step = 10
        back = brdf_pb2.Session.FromString(session.SerializeToString())
        self.assertEqual(back, session)
        self.assertTrue(back.plan.sample_rotation.alpha.HasField("step"))
        self.assertFalse(back.plan.sample_rotation.alpha.HasField("start"))


class Plans(unittest.TestCase):
    def test_example_plans_parse(self):
        files = sorted(glob.glob(os.path.join(ROOT, "examples", "plans", "*.json")))
        self.assertGreater(len(files), 0)
        for path in files:
            plan = to_plan(path)
            self.assertTrue(plan.name, path)
            self.assertIsNotNone(plan.WhichOneof("method"), path)

    def test_dict_json_text_and_snake_case(self):
        d = {"name": "n", "sampleRotation": {"alpha": {"step": 10}}}
        self.assertEqual(to_plan(d).sample_rotation.alpha.step, 10)
        self.assertEqual(to_plan('{"name": "t", "sample_fixed": {"targets": [{"theta_i": 5}]}}')
                         .sample_fixed.targets[0].theta_i, 5)
        plan = plan_pb2.Plan(name="p")
        self.assertIs(to_plan(plan), plan)

    def test_mistakes_name_the_source(self):
        with self.assertRaisesRegex(ValueError, "sampleRotaton"):
            to_plan({"sampleRotaton": {}})
        with self.assertRaisesRegex(ValueError, "no-such-plan.json"):
            to_plan("no-such-plan.json")
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            f.write('{"name": "x",\n "oops"}')
        self.addCleanup(os.unlink, f.name)
        with self.assertRaisesRegex(ValueError, f"{os.path.basename(f.name)}.*line 2"):
            to_plan(f.name)


class Names(unittest.TestCase):
    def test_both_ways(self):
        self.assertEqual(names.to_enum("Delaunay", names.METHODS, "method"),
                         brdf_pb2.INTERPOLATION_METHOD_DELAUNAY)
        self.assertEqual(names.to_enum(None, names.METHODS, "method"), 0)
        self.assertEqual(names.to_enum(brdf_pb2.QUANTITY_RADIANCE, names.QUANTITIES, "q"),
                         brdf_pb2.QUANTITY_RADIANCE)
        self.assertEqual(names.state_name(brdf_pb2.SESSION_STATE_AWAITING_OPERATOR),
                         "awaiting_operator")
        self.assertEqual(names.status_name(brdf_pb2.INTERPOLATION_STATUS_EMPTY_OCTANT),
                         "empty_octant")
        self.assertEqual(names.prompt_kind_name(plan_pb2.PROMPT_KIND_MOUNT_WHITE), "mount_white")
        with self.assertRaisesRegex(ValueError, "octant, delaunay, nearest"):
            names.to_enum("kriging", names.METHODS, "method")

    def test_coordinates_in_options_and_export_requests(self):
        from brdf_client.export import export_request
        from brdf_client.interpolation import interpolation_options
        half = brdf_pb2.INTERPOLATION_COORDINATES_HALF_DIFFERENCE
        for name in ("half-diff", "half_difference", "Half-Diff"):
            self.assertEqual(interpolation_options(coordinates=name).coordinates, half)
        self.assertIsNone(interpolation_options(coordinates=None))
        self.assertEqual(interpolation_options(coordinates="incidence").coordinates,
                         brdf_pb2.INTERPOLATION_COORDINATES_INCIDENCE)
        with self.assertRaisesRegex(ValueError, "unknown coordinates 'polar'"):
            interpolation_options(coordinates="polar")
        self.assertEqual(export_request("3", "merl", coordinates="half-diff").options.coordinates,
                         half)
        with self.assertRaisesRegex(ValueError, "coordinates are for grid, MERL and RGL"):
            export_request("3", "csv", coordinates="half-diff")

    def test_trend_in_options_and_export_requests(self):
        from brdf_client.export import export_request
        from brdf_client.interpolation import interpolation_options
        bivariate = brdf_pb2.INTERPOLATION_TREND_BIVARIATE
        self.assertEqual(interpolation_options(trend="bivariate").trend, bivariate)
        self.assertEqual(interpolation_options(trend="Bivariate").trend, bivariate)
        self.assertEqual(interpolation_options(trend="none").trend,
                         brdf_pb2.INTERPOLATION_TREND_NONE)
        # Both options travel together.
        both = interpolation_options(coordinates="half-diff", trend="bivariate")
        self.assertEqual(both.coordinates, brdf_pb2.INTERPOLATION_COORDINATES_HALF_DIFFERENCE)
        self.assertEqual(both.trend, bivariate)
        with self.assertRaisesRegex(ValueError, "unknown trend 'quadratic'"):
            interpolation_options(trend="quadratic")
        self.assertEqual(export_request("3", "rgl", trend="bivariate").options.trend, bivariate)
        with self.assertRaisesRegex(ValueError, "trend is for grid, MERL and RGL"):
            export_request("3", "csv", trend="bivariate")


def reading_proto(rid, kind, radiance, theta_i=10.0, grid=(380.0, 4.0, 101)):
    r = brdf_pb2.Reading(id=rid, session_id="1", kind=kind, radiance=radiance,
                         reference_id=2 if kind == brdf_pb2.READING_KIND_SAMPLE else 0)
    r.pose.alpha, r.pose.beta, r.pose.delta = 10.0, 20.0, 30.0
    r.directions.theta_i, r.directions.phi_o = theta_i, 170.0
    r.iso.theta_i, r.iso.theta_o, r.iso.phi = theta_i, 25.0, 170.0
    r.grid.start_nm, r.grid.step_nm, r.grid.count = grid
    return r


class Conversions(unittest.TestCase):
    def test_readings_to_arrays(self):
        protos = [reading_proto(1, brdf_pb2.READING_KIND_DARK, [0.1] * 101),
                  reading_proto(2, brdf_pb2.READING_KIND_REFERENCE, [2.0] * 101),
                  reading_proto(3, brdf_pb2.READING_KIND_SAMPLE, list(np.linspace(0, 1, 101)))]
        rs = ReadingSet.from_protos(protos)
        self.assertEqual(len(rs), 3)
        self.assertEqual(list(rs.kinds), ["dark", "reference", "sample"])
        self.assertEqual(rs.poses.shape, (3, 4))
        np.testing.assert_array_equal(rs.poses[2], [10, 20, 0, 30])
        np.testing.assert_array_equal(rs.iso[2], [10, 25, 170])
        self.assertEqual(rs.spectra.shape, (3, 101))
        self.assertEqual(rs.wavelengths[0], 380.0)
        self.assertEqual(rs.wavelengths[-1], 780.0)
        self.assertEqual(list(rs.reference_ids), [0, 0, 2])
        self.assertEqual(len(rs.of_kind("sample")), 1)
        both = ReadingSet.concat([rs, rs.of_kind("dark")])
        self.assertEqual(list(both.ids), [1, 2, 3, 1])
        self.assertEqual(rs.index_of(3), 2)
        with self.assertRaises(KeyError):
            rs.index_of(99)
        self.assertEqual(len(ReadingSet.from_protos([])), 0)

    def test_readings_on_different_grids_are_refused(self):
        with self.assertRaisesRegex(ValueError, "different wavelength grid"):
            ReadingSet.from_protos([
                reading_proto(1, brdf_pb2.READING_KIND_DARK, [0.1] * 101),
                reading_proto(2, brdf_pb2.READING_KIND_DARK, [0.1] * 51, grid=(380, 8, 51))])

    def result_proto(self, ok=True, four=False):
        r = brdf_pb2.InterpolationResult(
            status=brdf_pb2.INTERPOLATION_STATUS_OK if ok else
            brdf_pb2.INTERPOLATION_STATUS_OUTSIDE_HULL,
            method=brdf_pb2.INTERPOLATION_METHOD_DELAUNAY, quantity=brdf_pb2.QUANTITY_BRDF,
            detail="d")
        if four:
            r.query.four.theta_i, r.query.four.phi_i = 30, 10
            r.query.four.theta_o, r.query.four.phi_o = 40, 170
        else:
            r.query.iso.theta_i, r.query.iso.theta_o, r.query.iso.phi = 30, 40, 160
        r.grid.start_nm, r.grid.step_nm, r.grid.count = 380, 4, 101
        if ok:
            r.spectrum.extend(np.linspace(0.1, 0.2, 101))
            for i, w in enumerate((0.1, 0.2, 0.3, 0.4)):
                r.vertices.add(reading_id=10 + i, coords=[30 + i, 40, 160], weight=w)
        return r

    def test_interpolation_result(self):
        r = InterpolationResult.from_proto(self.result_proto())
        self.assertTrue(r.ok)
        self.assertEqual((r.status, r.method, r.quantity, r.unit),
                         ("ok", "delaunay", "brdf", "sr⁻¹"))
        np.testing.assert_array_equal(r.query, [30, 40, 160])
        self.assertEqual(r.axes, ("theta_i", "theta_o", "phi"))
        np.testing.assert_array_equal(r.vertex_ids, [10, 11, 12, 13])
        self.assertEqual(r.vertex_coords.shape, (4, 3))
        self.assertAlmostEqual(float(r.weights.sum()), 1.0)
        self.assertAlmostEqual(r.at(382.0), 0.1 + 0.1 * 0.5 / 100)
        with self.assertRaises(ValueError):
            r.at(900)
        four = InterpolationResult.from_proto(self.result_proto(four=True))
        self.assertEqual(four.axes, ("theta_i", "phi_i", "theta_o", "phi_o"))
        np.testing.assert_array_equal(four.query, [30, 10, 40, 170])

    def test_batch_marks_failures_nan(self):
        batch = InterpolationBatch([InterpolationResult.from_proto(self.result_proto(ok))
                                    for ok in (True, False, True)])
        self.assertEqual(batch.spectra.shape, (3, 101))
        self.assertEqual(list(batch.ok), [True, False, True])
        self.assertTrue(np.all(np.isnan(batch.spectra[1])))
        self.assertEqual(list(batch.statuses), ["ok", "outside_hull", "ok"])
        self.assertTrue(np.isnan(batch.at(550)[1]))



class AdaptiveEventText(unittest.TestCase):
    def test_a_round_says_its_spend_and_cost(self):
        from brdf_client.events import Event
        event = brdf_pb2.SessionEvent(session_id="7", sequence=3)
        r = event.adaptive_round
        r.round = 2
        r.poses.add(alpha=10, beta=-35, delta=45)
        r.predicted_gain = 0.104
        r.uncertainty_left = 0.461
        r.readings_used = 200
        r.spent_rig_s = 1034
        r.spent_prompts = 31
        r.rig_s = 242
        r.prompts = 2
        text = Event.from_proto(event).describe()
        self.assertEqual(text, "round 2: 1 poses, predicted gain 0.104, uncertainty left 0.461, "
                               "chosen from 200 readings; spent 17.2 min of rig time and 31 "
                               "prompts, the round 4.0 min and 2 prompts more")


class Errors(unittest.TestCase):
    def test_rpc_error_becomes_brdf_error(self):
        class Failed(grpc.RpcError):
            def code(self):
                return grpc.StatusCode.NOT_FOUND

            def details(self):
                return "session 9: no such session; list sessions with ListSessions"

        e = BrdfError.from_rpc_error(Failed(), "Control.GetSession")
        self.assertEqual(e.code, grpc.StatusCode.NOT_FOUND)
        self.assertEqual(e.code_name, "NOT_FOUND")
        self.assertIn("no such session", e.message)
        self.assertEqual(str(e), "Control.GetSession: NOT_FOUND: " + e.message)

    def test_no_daemon_is_unavailable(self):
        with BrdfClient("127.0.0.1:1", "t" * 20, timeout=5) as client:
            with self.assertRaises(BrdfError) as caught:
                client.get_session("1")
            self.assertEqual(caught.exception.code, grpc.StatusCode.UNAVAILABLE)
            with self.assertRaises(BrdfError) as caught:
                list(client.readings("1"))
            self.assertEqual(caught.exception.code, grpc.StatusCode.UNAVAILABLE)
            with self.assertRaises(BrdfError) as caught:
                client.wait_ready(0.2)
            self.assertEqual(caught.exception.code, grpc.StatusCode.UNAVAILABLE)

    def test_direction_arguments_are_checked_before_calling(self):
        with BrdfClient("127.0.0.1:1") as client:
            with self.assertRaisesRegex(ValueError, "phi is missing"):
                client.interpolate("1", 30, 40)
            with self.assertRaisesRegex(ValueError, "together"):
                client.interpolate("1", 30, 40, phi_i=0)
            with self.assertRaisesRegex(ValueError, "not both"):
                client.interpolate("1", 30, 40, 160, phi_i=0, phi_o=160)
            with self.assertRaisesRegex(ValueError, "mutual TLS"):
                BrdfClient("127.0.0.1:1", client_certificate=b"x")


class ReadingBrdf(unittest.TestCase):
    """reading_spectrum recomputes the virtual sample's BRDF from raw radiance (geometry.md)."""

    def check(self, reference_beta):
        rs = synthetic.make_session(reference_beta=reference_beta)
        samples = rs.of_kind("sample")
        for row in range(0, len(samples), 7):
            d = samples.directions[row]
            truth = synthetic.virtual_brdf(*d, synthetic.WAVELENGTHS)
            f = reading_spectrum(rs, samples.ids[row], "brdf", synthetic.WHITE)
            np.testing.assert_allclose(f, truth, rtol=1e-9)

    def test_reference_at_normal_incidence(self):
        self.check(0.0)

    def test_reference_tilted(self):  # θi,ref = 30°: the cos θi,ref / cos θi factor matters
        self.check(30.0)

    def test_quantities_and_refusals(self):
        rs = synthetic.make_session()
        sid = rs.of_kind("sample").ids[0]
        radiance = reading_spectrum(rs, sid, "radiance")
        np.testing.assert_allclose(radiance, rs.spectra[rs.index_of(sid)] - synthetic.AMBIENT)
        r = reading_spectrum(rs, sid, "reflectance")
        white = rs.spectra[rs.index_of(rs.reference_ids[rs.index_of(sid)])] - synthetic.AMBIENT
        np.testing.assert_allclose(r, radiance / white)
        with self.assertRaisesRegex(ValueError, "not a sample"):
            reading_spectrum(rs, rs.of_kind("dark").ids[0])
        with self.assertRaisesRegex(ValueError, "unknown quantity"):
            reading_spectrum(rs, sid, "luminance")


class Figures(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.readings = synthetic.make_session()
        cls.fake = synthetic.FakeInterpolationClient(cls.readings)

        class Session:  # the two fields the figures show
            session_id = "synthetic"
            name = "demo grid, virtual paint"
        cls.session = Session()
        cls.out = output_dir("synthetic_figures")

    def test_candidates_lie_between_samples(self):
        iso = self.readings.of_kind("sample").iso
        cands = _common.candidate_queries(iso)
        self.assertGreater(len(cands), 0)
        self.assertTrue(np.all(cands >= iso.min(axis=0)) and np.all(cands <= iso.max(axis=0)))
        for c in cands:
            self.assertGreater(np.min(np.linalg.norm(iso - c, axis=1)), 0.0)

    def test_picked_query_blends_four_readings(self):
        r = _common.pick_query(self.fake, "s", self.readings.of_kind("sample"),
                               readings=self.readings)
        self.assertTrue(r.ok)
        self.assertEqual(len(r.vertices), 4)
        self.assertGreaterEqual(r.weights.min(), 0.1)
        v = vertex_spectra(self.readings, r)
        self.assertTrue(np.all(r.spectrum <= v.max(axis=0) + 1e-12))
        self.assertTrue(np.all(r.spectrum >= v.min(axis=0) - 1e-12))

    def test_no_readings_no_query(self):
        with self.assertRaisesRegex(RuntimeError, "too few"):
            _common.pick_query(self.fake, "s", self.readings.of_kind("sample").select(
                np.arange(2)))

    def test_polar_picks_in_plane_incidence_angles(self):
        samples = self.readings.of_kind("sample")
        # demo grid: α = 0 rows put θi = |β| at 15° steps in the plane of incidence
        self.assertEqual(polar.default_thetas(samples), [15.0, 30.0, 45.0, 60.0])
        dirs, signed = polar.queries_for(30.0)
        self.assertTrue(np.all(np.diff(signed) > 0))
        self.assertTrue(np.all(dirs[signed < 0, 2] == 0) and np.all(dirs[signed > 0, 2] == 180))
        np.testing.assert_array_equal(np.abs(signed), dirs[:, 1])
        self.assertEqual(int(np.sum(signed == 0)), 1)

    def assertPng(self, path):
        self.assertTrue(os.path.isfile(path), path)
        with open(path, "rb") as f:
            self.assertEqual(f.read(8), PNG_SIGNATURE)
        self.assertGreater(os.path.getsize(path), 20000, path)

    def test_all_three_figures(self):
        q = _common.pick_query(self.fake, "s", self.readings.of_kind("sample"),
                               readings=self.readings)
        data = _common.SessionData(self.session, self.readings, q)
        self.assertPng(fig7.plot(data, os.path.join(self.out, "fig7.png")))
        self.assertPng(fig8.plot(data, os.path.join(self.out, "fig8.png")))
        pdata = polar.gather(self.fake, "s", self.readings, title=data.title)
        self.assertEqual([c.theta_i for c in pdata.curves], [15.0, 30.0, 45.0, 60.0])
        for c in pdata.curves:
            self.assertGreater(len(c.measured_values), 0)
            self.assertTrue(np.any(np.isfinite(c.values)))
        self.assertPng(polar.plot(pdata, os.path.join(self.out, "polar.png")))
        text = describe(data)
        self.assertIn(": ok", text)
        for v in q.vertices:
            self.assertIn(f"vertex reading {v.reading_id:>6}", text)

    def test_a_failed_query_is_drawn_not_raised(self):
        r = self.fake.interpolate("s", 0.0, 0.0, 0.0)
        self.assertFalse(r.ok)
        data = _common.SessionData(self.session, self.readings, r)
        self.assertPng(fig7.plot(data, os.path.join(self.out, "fig7_failed.png")))
        self.assertPng(fig8.plot(data, os.path.join(self.out, "fig8_failed.png")))


if __name__ == "__main__":
    unittest.main()
