"""brdf_client against a running brdfd driving brdf-sim (both started as processes).

setUpClass runs one small sample-rotation plan to completion, answering the operator's prompts
the way an operator would — mounting the white standard, closing the shutter, mounting the sample
on the simulator through its Modbus control unit — and every test then reads that session.
Exit code 77 (ctest: skipped) when brdfd or brdf-sim is not built.
"""

import json
import os
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, HERE)

import grpc  # noqa: E402

import live_rig  # noqa: E402
from brdf_client import BrdfClient, BrdfError, brdf_pb2, names  # noqa: E402
from brdf_client.figures import _common  # noqa: E402
from brdf_client.spectra import reading_spectrum, vertex_spectra  # noqa: E402

# Small but enough for the octant method: 3 detector positions × 3 tilts × β every 15°, with a
# white reference and a dark reading at every detector position.
PLAN = {
    "name": "pyclient test grid",
    "sampleDescription": "virtual paint of brdf-sim",
    "sampleRotation": {
        "delta": {"start": 0, "stop": 60, "step": 30},
        "alpha": {"start": 0, "stop": 40, "step": 20},
        "beta": {"step": 15},
    },
    "reference": {"perDetectorPosition": True},
    "dark": {"withEachReference": True},
    "measurement": {"integrationMs": 0, "averages": 1},
    "retry": {"maxAttempts": 3, "backoffMs": 10},
}
# What the operator does for each prompt on the simulated rig.
PROMPT_ACTIONS = {
    "mount_white": "white",
    "close_shutter": "dark",
    "mount_sample": "sample",
}
WAVELENGTHS = 380.0 + 4.0 * np.arange(101)


class LiveSession(unittest.TestCase):
    rig = None
    client = None
    session = None
    final = None
    events = []
    prompts = []

    @classmethod
    def setUpClass(cls):
        sim, daemon = live_rig.binaries()
        cls.rig = live_rig.LiveRig(sim, daemon)
        cls.rig.start()
        cls.client = BrdfClient(cls.rig.address, cls.rig.operator_token)
        try:
            cls.client.wait_ready(10)
            cls.session = cls.client.submit_plan(PLAN, start_now=True)
            cls.final = cls.client.wait(cls.session.session_id, on_event=cls.events.append,
                                        on_prompt=cls._act, timeout=180,
                                        stop_states=("paused",))
            if names.state_name(cls.final.state) != "completed":
                raise AssertionError(f"session ended {names.state_name(cls.final.state)}: "
                                     f"{cls.final.last_fault.reason or cls.final.end_reason}")
        except Exception:
            print(f"brdfd log:\n{cls.rig.log('brdfd')}\nbrdf-sim log:\n{cls.rig.log('sim')}",
                  file=sys.stderr)
            cls.tearDownClass()
            raise
        cls.readings = cls.client.load_readings(cls.session.session_id)

    @classmethod
    def _act(cls, prompt):
        cls.prompts.append(prompt)
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

    # --- the session -----------------------------------------------------------------------------

    def test_session_ran_to_completion(self):
        s = self.final
        self.assertEqual(names.state_name(s.state), "completed", s.end_reason)
        self.assertEqual(s.progress.done_steps, s.progress.total_steps)
        self.assertEqual(s.progress.done_samples, s.summary.sample_readings)
        self.assertGreater(s.summary.sample_readings, 0)
        self.assertEqual(s.name, PLAN["name"])
        again = self.client.get_session(self.session.session_id)
        self.assertEqual(again.plan.name, PLAN["name"])
        self.assertTrue(again.plan.HasField("sample_rotation"))

    def test_events_and_prompts(self):
        kinds = [e.kind for e in self.events]
        self.assertEqual(kinds[0], "snapshot")
        self.assertIn("step_completed", kinds)
        self.assertIn("state_changed", kinds)
        # Every prompt was seen once and answered: one per manual action of the plan.
        self.assertEqual(len({p.step_index for p in self.prompts}),
                         self.final.summary.operator_interventions)
        last = [e for e in self.events if e.kind == "step_completed"][-1]
        self.assertEqual(last.data.progress.done_steps, last.data.progress.total_steps)
        self.assertTrue(all(isinstance(e.describe(), str) for e in self.events))

    def test_listed_and_rig_status(self):
        ids = [s.session_id for s in self.client.list_sessions()]
        self.assertIn(self.session.session_id, ids)
        done = self.client.list_sessions(states="completed")
        self.assertTrue(all(names.state_name(s.state) == "completed" for s in done))
        self.assertIn(self.session.session_id, [s.session_id for s in done])
        # Paging: one per page still lists every session.
        self.assertEqual([s.session_id for s in self.client.list_sessions(page_size=1)], ids)
        rig = self.client.rig_status()
        states = {d.name: d.state for d in rig.devices}
        self.assertEqual(states.get("meter"), brdf_pb2.CONNECTION_STATE_CONNECTED, rig)
        self.assertEqual(states.get("stage"), brdf_pb2.CONNECTION_STATE_CONNECTED, rig)

    def test_session_events_history(self):
        """list_session_events: the completed session's states oldest first (QUEUED, RUNNING, the
        prompts' AWAITING_OPERATOR, COMPLETED), ids increasing, times set and not going back."""
        sid = self.session.session_id
        events = self.client.list_session_events(sid)
        self.assertGreaterEqual(len(events), 3, events)
        self.assertEqual(collapsed_states(events), ["queued", "running", "completed"], events)
        self.assertIn("awaiting_operator", [names.state_name(e.state) for e in events])
        self.assertEqual(names.state_name(events[0].state), "queued")
        self.assertEqual(events[0].at.ToMilliseconds(),
                         self.session.created_at.ToMilliseconds())
        for before, after in zip(events, events[1:]):
            self.assertGreater(after.id, before.id)
            self.assertGreaterEqual(after.at.ToNanoseconds(), before.at.ToNanoseconds())
        for e in events:
            self.assertTrue(e.HasField("at") and e.at.seconds > 0, e)
        now = self.client.get_session(sid)
        self.assertEqual(events[-1].reason, now.state_reason)
        # An analyst reads the same history; an unknown or malformed id is refused.
        with BrdfClient(self.rig.address, self.rig.analyst_token) as analyst:
            self.assertEqual(analyst.list_session_events(sid), events)
        e = self.assertCode(grpc.StatusCode.NOT_FOUND, self.client.list_session_events, "987654")
        self.assertEqual(e.method, "Control.ListSessionEvents")
        self.assertIn("987654", e.message)
        self.assertCode(grpc.StatusCode.INVALID_ARGUMENT, self.client.list_session_events,
                        "not-a-session")

    def test_adaptive_rounds_of_a_fixed_plan(self):
        """list_adaptive_rounds: none for a session of a fixed plan (an analyst may ask); an
        unknown id is refused naming the call."""
        with BrdfClient(self.rig.address, self.rig.analyst_token) as analyst:
            self.assertEqual(analyst.list_adaptive_rounds(self.session.session_id), [])
        e = self.assertCode(grpc.StatusCode.NOT_FOUND, self.client.list_adaptive_rounds, "987654")
        self.assertEqual(e.method, "Control.ListAdaptiveRounds")

    # --- readings --------------------------------------------------------------------------------

    def test_readings_arrays(self):
        r = self.readings
        s = self.final.summary
        n = len(r)
        self.assertEqual(n, s.sample_readings + s.reference_readings + s.dark_readings)
        self.assertEqual(len(r.of_kind("sample")), s.sample_readings)
        self.assertEqual(len(r.of_kind("reference")), s.reference_readings)
        self.assertEqual(len(r.of_kind("dark")), s.dark_readings)
        self.assertEqual(r.poses.shape, (n, 4))
        self.assertEqual(r.directions.shape, (n, 4))
        self.assertEqual(r.iso.shape, (n, 3))
        self.assertEqual(r.spectra.shape, (n, 101))
        np.testing.assert_allclose(r.wavelengths, WAVELENGTHS)
        self.assertTrue(np.all(np.diff(r.ids) > 0), "ids increase in the order taken")
        samples = r.of_kind("sample")
        self.assertTrue(set(samples.reference_ids) <= set(r.of_kind("reference").ids))
        self.assertTrue(set(samples.dark_ids) <= set(r.of_kind("dark").ids))
        # The poses are the plan's grid (stage readings: within a count, 1/27.8°, of the plan's
        # angles), and the directions follow from them (geometry.md).
        for column, grid in ((3, [0.0, 30.0, 60.0]), (0, [0.0, 20.0, 40.0])):
            nearest = np.array(grid)[np.argmin(np.abs(samples.poses[:, column, None] - grid), 1)]
            np.testing.assert_allclose(samples.poses[:, column], nearest, atol=0.04)
            self.assertEqual(set(nearest), set(grid))
        a, b, d = (np.radians(samples.poses[:, k]) for k in (0, 1, 3))
        np.testing.assert_allclose(np.cos(np.radians(samples.directions[:, 0])),
                                   np.cos(a) * np.cos(b), atol=1e-6)
        np.testing.assert_allclose(np.cos(np.radians(samples.directions[:, 2])),
                                   np.cos(a) * np.cos(b - d), atol=1e-6)
        self.assertTrue(np.all(samples.spectra > 0))

    def test_readings_chunks_kinds_and_after_id(self):
        sid = self.session.session_id
        chunks = list(self.client.readings(sid, batch_size=7))
        self.assertTrue(all(len(c) <= 7 for c in chunks))
        np.testing.assert_array_equal(np.concatenate([c.ids for c in chunks]), self.readings.ids)
        darks = self.client.load_readings(sid, kinds="dark")
        self.assertTrue(len(darks) > 0 and np.all(darks.kinds == "dark"))
        both = self.client.load_readings(sid, kinds=["sample", "reference"])
        self.assertEqual(set(both.kinds), {"sample", "reference"})
        middle = int(self.readings.ids[len(self.readings) // 2])
        after = np.concatenate([c.ids for c in self.client.readings(sid, after_id=middle)])
        np.testing.assert_array_equal(after, self.readings.ids[self.readings.ids > middle])

    def test_reading_brdf_matches_the_virtual_sample(self):
        """BRDF recomputed from raw readings (spectra.reading_spectrum) is the simulator's truth
        within the meter's noise: the units and the reference/dark bookkeeping are right."""
        samples = self.readings.of_kind("sample")
        errors = []
        for row in range(0, len(samples), max(1, len(samples) // 6)):
            ti, pi, to, po = samples.directions[row]
            truth = simulator_truth(ti, pi, to, po)
            f = reading_spectrum(self.readings, samples.ids[row], "brdf", 0.99)
            band = (WAVELENGTHS >= 450) & (WAVELENGTHS <= 700)  # away from the lamp's dim blue end
            errors.append(np.median(np.abs(f[band] / truth[band] - 1)))
        self.assertLess(max(errors), 0.05, errors)

    # --- interpolation ---------------------------------------------------------------------------

    def picked(self):
        return _common.pick_query(self.client, self.session.session_id,
                                  self.readings.of_kind("sample"), "octant",
                                  readings=self.readings)

    def test_interpolate_between_vertex_spectra(self):
        r = self.picked()
        self.assertTrue(r.ok, r.detail)
        self.assertEqual((r.method, r.quantity, r.unit), ("octant", "brdf", "sr⁻¹"))
        self.assertEqual(len(r.vertices), 4)
        self.assertEqual(r.spectrum.shape, (101,))
        np.testing.assert_allclose(r.wavelengths, WAVELENGTHS)
        self.assertTrue(np.all(r.weights >= 0))
        self.assertAlmostEqual(float(r.weights.sum()), 1.0, places=9)
        self.assertFalse(any(np.allclose(r.query, c) for c in self.readings.iso),
                         "the query lies between samples")
        v = vertex_spectra(self.readings, r, 0.99)
        tol = 1e-9 * np.max(np.abs(v))
        self.assertTrue(np.all(r.spectrum >= v.min(axis=0) - tol))
        self.assertTrue(np.all(r.spectrum <= v.max(axis=0) + tol))
        # The daemon's blend is exactly Σ weight · vertex spectrum of the stored readings.
        np.testing.assert_allclose(r.weights @ v, r.spectrum, rtol=1e-6)
        # The same query again, as the user would type it.
        again = self.client.interpolate(self.session.session_id, *r.query)
        np.testing.assert_array_equal(again.spectrum, r.spectrum)
        np.testing.assert_array_equal(again.vertex_ids, r.vertex_ids)

    def test_interpolate_forms_methods_and_quantities(self):
        sid = self.session.session_id
        q = self.picked().query
        iso = self.client.interpolate(sid, *q)
        four = self.client.interpolate(sid, q[0], q[1], phi_i=0.0, phi_o=q[2])
        np.testing.assert_allclose(four.spectrum, iso.spectrum, rtol=1e-12)
        nearest = self.client.interpolate(sid, *q, method="nearest")
        self.assertEqual(len(nearest.vertices), 1)
        self.assertAlmostEqual(nearest.vertices[0].weight, 1.0)
        np.testing.assert_allclose(
            nearest.spectrum, reading_spectrum(self.readings, nearest.vertex_ids[0]), rtol=1e-6)
        radiance = self.client.interpolate(sid, *q, quantity="radiance")
        self.assertEqual((radiance.quantity, radiance.unit), ("radiance", "W·m⁻²·sr⁻¹·nm⁻¹"))
        np.testing.assert_array_equal(radiance.vertex_ids, iso.vertex_ids)
        np.testing.assert_allclose(
            radiance.spectrum,
            radiance.weights @ vertex_spectra(self.readings, radiance), rtol=1e-6)
        delaunay = self.client.interpolate(sid, *q, method="delaunay")
        self.assertEqual(delaunay.method, "delaunay")
        if delaunay.ok:
            self.assertAlmostEqual(float(delaunay.weights.sum()), 1.0, places=9)

    def test_interpolate_with_uncertainty(self):
        """uncertainty=True: the measurement part carries the white standard shared by every
        vertex whole (at least Σ w·u_white of the vertices' stored budgets), the combined is the
        quadrature sum of it and the interpolation term, and the batch gives the same."""
        sid = self.session.session_id
        q = self.picked().query
        r = self.client.interpolate(sid, *q, uncertainty=True)
        self.assertIsNone(self.client.interpolate(sid, *q).uncertainty)
        u = r.uncertainty
        self.assertIsNotNone(u)
        for part in (u.measurement, u.shared, u.interpolation, u.combined):
            self.assertEqual(part.shape, (101,))
        self.assertTrue(np.all(u.measurement > 0))
        # The parts are float32 on the wire: the quadrature sum holds to a float's rounding.
        np.testing.assert_allclose(u.combined, np.hypot(u.measurement, u.interpolation),
                                   rtol=1.2e-7)
        budgets = dict(zip(self.readings.ids, self.readings.budgets))
        white = sum(v.weight * budgets[v.reading_id].components["white_standard"].contribution
                    for v in r.vertices)
        self.assertTrue(np.all(u.shared >= white * (1 - 1.2e-7)))
        # The batch sends the two parts and not combined: computed here, the same bits.
        batch = self.client.interpolate_batch(sid, [q, q], uncertainty=True, progress=False)
        np.testing.assert_array_equal(batch.u_combined[1], u.combined)
        np.testing.assert_array_equal(batch.u_measurement[0], u.measurement)
        np.testing.assert_array_equal(batch.u_interpolation[0], u.interpolation)
        self.assertEqual(batch[0].uncertainty.shared.shape, (0,))
        shared = self.client.interpolate_batch(sid, [q], uncertainty=True,
                                               uncertainty_shared=True, progress=False)
        np.testing.assert_array_equal(shared[0].uncertainty.shared, u.shared)

    def test_appearance_colour_and_sphere(self):
        sid = self.session.session_id
        look = self.client.appearance(sid, sphere_size=32, mirror_phi=True, reciprocity=True)
        self.assertEqual([i.name for i in look.images], ["D65", "A"])
        d65, a = look["D65"], look["A"]
        self.assertEqual(d65.sphere.shape, (32, 32, 4))
        self.assertEqual(d65.sphere[0, 0, 3], 0)  # a corner: outside the disc
        self.assertRegex(d65.hex, r"^#[0-9a-f]{6}$")
        self.assertNotEqual(d65.hex, "#000000")
        self.assertGreater(d65.xyz[1], 0)
        lit = d65.counts["disc"] - d65.counts["unlit"]
        self.assertEqual(sum(d65.counts[k] for k in ("interpolated", "fallback", "model", "empty")),
                         lit)
        self.assertEqual(len(look.reflectance), 101)
        self.assertEqual(look.wavelengths[0], 380)
        # Under A the colour sits toward red: larger x than under D65.
        self.assertGreater(a.xy[0], d65.xy[0] + 0.05)
        with self.assertRaises(ValueError):
            self.client.appearance(sid, "F2")
        with self.assertRaises(BrdfError) as e:
            self.client.appearance(sid, sphere_size=600)
        self.assertEqual(e.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("sphere_size", str(e.exception))

    def test_interpolate_batch_matches_single_calls(self):
        sid = self.session.session_id
        cands = _common.candidate_queries(self.readings.of_kind("sample").iso, limit=5)
        dirs = np.vstack([cands, [[0.0, 0.0, 0.0], [89.0, 89.0, 180.0]]])  # two edges too
        batch = self.client.interpolate_batch(sid, dirs, chunk_size=2)
        self.assertEqual(len(batch), len(dirs))
        self.assertEqual(batch.spectra.shape, (len(dirs), 101))
        for i, d in enumerate(dirs):
            one = self.client.interpolate(sid, *d)
            self.assertEqual(batch[i].status, one.status)
            np.testing.assert_allclose(batch[i].query, d)
            if one.ok:
                np.testing.assert_array_equal(batch.spectra[i], one.spectrum)
            else:
                self.assertTrue(np.all(np.isnan(batch.spectra[i])))
        self.assertEqual(list(batch.ok), [r.ok for r in batch])

    def test_interpolate_in_half_difference_coordinates(self):
        """coordinates="half-diff" reaches the daemon: other answers than incidence, each still
        the weighted blend of the readings it names; incidence again afterwards is unchanged."""
        sid = self.session.session_id
        dirs = _common.candidate_queries(self.readings.of_kind("sample").iso, limit=6)
        incidence = self.client.interpolate_batch(sid, dirs, method="delaunay")
        half = self.client.interpolate_batch(sid, dirs, method="delaunay", coordinates="half-diff")
        again = self.client.interpolate_batch(sid, dirs, method="delaunay",
                                              coordinates="incidence")
        np.testing.assert_array_equal(again.spectra, incidence.spectra)
        both = np.asarray(incidence.ok) & np.asarray(half.ok)
        self.assertTrue(both.any(), "no direction answered in both coordinates")
        self.assertFalse(np.array_equal(half.spectra[both], incidence.spectra[both]))
        for r in half:
            if r.ok:
                self.assertAlmostEqual(float(r.weights.sum()), 1.0, places=9)
                np.testing.assert_allclose(
                    r.spectrum, r.weights @ vertex_spectra(self.readings, r), rtol=1e-6)
        one = self.client.interpolate(sid, *dirs[0], method="delaunay", coordinates="half_difference")
        self.assertEqual(one.status, half[0].status)
        if one.ok:
            np.testing.assert_array_equal(one.spectrum, half.spectra[0])
        with self.assertRaises(ValueError):
            self.client.interpolate(sid, *dirs[0], coordinates="polar")

    # --- errors ----------------------------------------------------------------------------------

    def assertCode(self, code, fn, *args, **kwargs):
        with self.assertRaises(BrdfError) as caught:
            fn(*args, **kwargs)
        self.assertEqual(caught.exception.code, code, str(caught.exception))
        self.assertTrue(caught.exception.message)
        return caught.exception

    def test_wrong_token_is_unauthenticated(self):
        with BrdfClient(self.rig.address, "not-the-token-at-all-0123") as wrong:
            e = self.assertCode(grpc.StatusCode.UNAUTHENTICATED, wrong.get_session,
                                self.session.session_id)
            self.assertEqual(e.code_name, "UNAUTHENTICATED")
            self.assertCode(grpc.StatusCode.UNAUTHENTICATED,
                            lambda: list(wrong.readings(self.session.session_id)))
        with BrdfClient(self.rig.address, "") as none:  # "": no token at all (not $BRDF_TOKEN)
            self.assertCode(grpc.StatusCode.UNAUTHENTICATED, none.rig_status)
            self.assertCode(grpc.StatusCode.UNAUTHENTICATED, none.who_am_i)

    def test_analyst_reads_but_may_not_operate(self):
        me = self.client.who_am_i()
        self.assertEqual((me.role, me.server), ("operator", "brdfd"))
        with BrdfClient(self.rig.address, self.rig.analyst_token) as analyst:
            who = analyst.who_am_i()
            self.assertEqual((who.role, who.server), ("analyst", "brdfd"))
            self.assertNotEqual(who.name, me.name)
            self.assertEqual(analyst.get_session(self.session.session_id).session_id,
                             self.session.session_id)
            self.assertTrue(analyst.interpolate(self.session.session_id, 30, 30, 90).status)
            self.assertCode(grpc.StatusCode.PERMISSION_DENIED, analyst.submit_plan, PLAN)

    def test_errors_carry_code_and_message(self):
        self.assertCode(grpc.StatusCode.NOT_FOUND, self.client.get_session, "999999")
        self.assertCode(grpc.StatusCode.INVALID_ARGUMENT, self.client.get_session, "no-such-id")
        bad = dict(PLAN, sampleRotation={"alpha": {"step": -10}})
        e = self.assertCode(grpc.StatusCode.INVALID_ARGUMENT, self.client.submit_plan, bad)
        self.assertIn("sampleRotation.alpha.step", e.message)
        checked = self.client.validate_plan(bad)
        self.assertFalse(checked.valid)
        self.assertIn("sampleRotation.alpha.step", [p.field_path for p in checked.problems])
        self.assertTrue(self.client.validate_plan(PLAN).valid)
        self.assertCode(grpc.StatusCode.INVALID_ARGUMENT, self.client.interpolate,
                        self.session.session_id, 95, 30, 90)
        self.assertCode(grpc.StatusCode.FAILED_PRECONDITION, self.client.resume,
                        self.session.session_id)

    # --- the operator's verbs on a second session -------------------------------------------------

    def test_start_pause_resume_abort(self):
        plan = {"name": "pyclient verbs",
                "poseList": {"poses": [{"alpha": 0, "beta": 10, "delta": 30},
                                       {"alpha": 10, "beta": 20, "delta": 30}]}}
        s = self.client.submit_plan(plan)
        sid = s.session_id
        self.assertEqual(names.state_name(s.state), "queued")
        self.client.start(sid)
        s = wait_for_state(self.client, sid, {"awaiting_operator"})  # the first white reference
        self.assertEqual(names.prompt_kind_name(s.pending_prompt.kind), "mount_white")
        s = self.client.pause(sid, immediate=True)
        self.assertEqual(names.state_name(s.state), "paused")
        self.assertCode(grpc.StatusCode.FAILED_PRECONDITION, self.client.answer_prompt, sid)
        self.client.resume(sid)
        s = wait_for_state(self.client, sid, {"awaiting_operator"})  # asked again after resume
        s = self.client.abort(sid, reason="test over")
        self.assertEqual(names.state_name(s.state), "aborted")
        self.assertIn("test over", self.client.get_session(sid).end_reason)
        # The history has the pause and the resume (an immediate pause: no PAUSING), in order.
        events = self.client.list_session_events(sid)
        self.assertEqual(collapsed_states(events),
                         ["queued", "running", "paused", "running", "aborted"], events)
        self.assertEqual([e.id for e in events], sorted({e.id for e in events}))

    # --- figures -----------------------------------------------------------------------------------

    def test_figures_command_writes_three_pngs(self):
        out = os.environ.get("BRDF_TEST_OUTPUT_DIR") or tempfile.mkdtemp(prefix="brdf_fig_")
        out = os.path.join(out, "live_figures")
        env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "clients", "python"))
        done = subprocess.run(
            [sys.executable, "-m", "brdf_client.figures", "--address", self.rig.address,
             "--token", self.rig.analyst_token, "--session", self.session.session_id,
             "--out", out], env=env, capture_output=True, text=True, timeout=120, check=False)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn(": ok", done.stdout)
        for name in ("fig7.png", "fig8.png", "polar.png"):
            path = os.path.join(out, name)
            self.assertTrue(os.path.isfile(path), path)
            with open(path, "rb") as f:
                head = f.read(8)
            self.assertEqual(head, b"\x89PNG\r\n\x1a\n", path)
            self.assertGreater(os.path.getsize(path), 20000, path)


def wait_for_state(client, session_id, wanted, timeout=30.0):
    """Polls until the session is in one of `wanted` (short names); fails the test otherwise."""
    until = time.monotonic() + timeout
    while True:
        s = client.get_session(session_id)
        if names.state_name(s.state) in wanted:
            return s
        if time.monotonic() > until:
            raise AssertionError(f"session {session_id} is {names.state_name(s.state)}, "
                                 f"not {wanted}, after {timeout} s")
        time.sleep(0.05)


def collapsed_states(events):
    """The short state names of SessionStateEvents in order, without the prompts'
    AWAITING_OPERATOR and without repeats of a state (a changed reason)."""
    states = []
    for e in events:
        name = names.state_name(e.state)
        if name != "awaiting_operator" and (not states or states[-1] != name):
            states.append(name)
    return states


def simulator_truth(theta_i, phi_i, theta_o, phi_o):
    """The virtual sample's BRDF (sr⁻¹, 101 bands) from `brdf-sim truth --json`."""
    sim, _ = live_rig.binaries()
    out = subprocess.run([sim, "truth", "--theta-i", repr(theta_i), "--theta-o", repr(theta_o),
                          "--phi-i", repr(phi_i), "--phi-o", repr(phi_o), "--json"],
                         capture_output=True, text=True, check=True, timeout=30)
    data = json.loads(out.stdout)
    np.testing.assert_allclose(data["wavelength_nm"], WAVELENGTHS)
    return np.array(data["brdf"])


if __name__ == "__main__":
    sim_path, daemon_path = live_rig.binaries()
    if not sim_path or not daemon_path:
        print(f"skipped: brdf-sim or brdfd is not built in {live_rig.build_dir()} "
              f"(brdf-sim: {sim_path}, brdfd: {daemon_path})")
        sys.exit(77)
    unittest.main()
