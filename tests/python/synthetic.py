"""A synthetic session for testing brdf_client's figure code without a daemon.

Readings are made the way the rig makes them (docs/geometry.md): holder poses of the
sample-rotation method → lamp and detector directions in the sample's frame; radiance of a
virtual sample (Lambert + a Phong lobe) under a lamp, a white reference at normal incidence, and
a dark reading. Interpolation answers come from tools/check/octant_reference.py, the independent
NumPy version of the paper's method; FakeInterpolationClient offers the two BrdfClient calls the
figure code makes (interpolate, interpolate_batch) on top of it, in place of a live brdfd.
"""

import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, os.path.join(ROOT, "tools", "check"))

import octant_reference  # noqa: E402  pylint: disable=wrong-import-position

from brdf_client import InterpolationBatch, InterpolationResult, ReadingSet, Vertex  # noqa: E402
from brdf_client.spectra import reading_spectrum  # noqa: E402

WAVELENGTHS = 380.0 + 4.0 * np.arange(101)
AMBIENT = 5e-6
WHITE = 0.99


def lamp_irradiance(wl):
    """W·m⁻²·nm⁻¹ at normal incidence: a warm lamp, 0.25 at 560 nm."""
    return 0.25 * (wl / 560.0) ** 2


def local_vector(theta, phi):
    t, p = np.radians(theta), np.radians(phi)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


def virtual_brdf(theta_i, phi_i, theta_o, phi_o, wl):
    """sr⁻¹: a warm paint (a Gaussian albedo bump at 610 nm over a flat base) plus a grey,
    energy-normalised Blinn-Phong lobe, like brdf-sim's AnalyticBrdf::PaintLike."""
    u = (np.asarray(wl, float) - 610.0) / 90.0
    diffuse = (0.25 + 0.45 * np.exp(-u * u)) / np.pi
    h = local_vector(theta_i, phi_i) + local_vector(theta_o, phi_o)
    cos_h = h[2] / np.linalg.norm(h)
    return diffuse + 0.08 * (60 + 8) / (8 * np.pi) * max(cos_h, 0.0) ** 60


def pose_to_directions(alpha, beta, gamma, delta):
    """(θi, φi, θo, φo), degrees, of a holder pose (geometry.md)."""
    a, b, g, d = np.radians([alpha, beta, gamma, delta])
    rz = np.array([[np.cos(b), -np.sin(b), 0], [np.sin(b), np.cos(b), 0], [0, 0, 1]])
    ry = np.array([[np.cos(-a), 0, np.sin(-a)], [0, 1, 0], [-np.sin(-a), 0, np.cos(-a)]])
    rx = np.array([[1, 0, 0], [0, np.cos(g), -np.sin(g)], [0, np.sin(g), np.cos(g)]])
    r = rz @ ry @ rx
    t, bt, n = r @ np.array([0, 1.0, 0]), r @ np.array([0, 0, 1.0]), r @ np.array([1.0, 0, 0])
    out = []
    for v in (np.array([1.0, 0, 0]), np.array([np.cos(d), np.sin(d), 0])):
        theta = np.degrees(np.arccos(np.clip(v @ n, -1, 1)))
        phi = np.degrees(np.arctan2(v @ bt, v @ t))
        out += [theta, phi]
    return tuple(out)


def iso_of(theta_i, phi_i, theta_o, phi_o):
    """(θi, θo, φ): φ = |φo − φi| folded into [0, 180]; 0 where θi or θo is 0."""
    if theta_i < 1e-9 or theta_o < 1e-9:
        return (theta_i, theta_o, 0.0)
    diff = abs(phi_o - phi_i) % 360.0
    return (theta_i, theta_o, 360.0 - diff if diff > 180.0 else diff)


def demo_poses(deltas=(0, 22.5, 45), alphas=(0, 20, 40), beta_step=15, theta_max=89.999):
    """The sample-rotation loops of examples/plans/demo.json."""
    poses = []
    for d in deltas:
        for a in alphas:
            for b in np.arange(-180 + beta_step, 180 + 1e-9, beta_step):
                ti, _, to, _ = pose_to_directions(a, b, 0, d)
                if ti <= theta_max and to <= theta_max:
                    poses.append((a, float(b), 0.0, d))
    return poses


def make_session(poses=None, noise=0.0, seed=1, reference_beta=0.0):
    """A ReadingSet as brdfd would stream it: per δ one dark, one white reference (holder at
    α = 0, β = reference_beta, so θi,ref = |reference_beta|), then the samples."""
    rng = np.random.default_rng(seed)
    poses = poses if poses is not None else demo_poses()
    rows = []
    next_id = 1
    e = lamp_irradiance(WAVELENGTHS)
    by_delta = {}
    for p in poses:
        by_delta.setdefault(p[3], []).append(p)
    for delta, group in by_delta.items():
        dark_id, ref_id = next_id, next_id + 1
        next_id += 2
        ref_pose = (0, reference_beta, 0, delta)
        ref_dirs = pose_to_directions(*ref_pose)
        rows.append((dark_id, "dark", ref_pose, ref_dirs, np.full(101, AMBIENT), 0, 0))
        white = e * WHITE / np.pi * np.cos(np.radians(ref_dirs[0])) + AMBIENT
        rows.append((ref_id, "reference", ref_pose, ref_dirs, white, 0, dark_id))
        for pose in group:
            dirs = pose_to_directions(*pose)
            f = virtual_brdf(*dirs, WAVELENGTHS)
            radiance = e * f * np.cos(np.radians(dirs[0])) + AMBIENT
            radiance = radiance * (1 + noise * rng.standard_normal(101))
            rows.append((next_id, "sample", pose, dirs, radiance, ref_id, dark_id))
            next_id += 1
    n = len(rows)
    return ReadingSet(
        ids=np.array([r[0] for r in rows], dtype=np.int64),
        kinds=np.array([r[1] for r in rows], dtype=object),
        step_index=np.arange(n), poses=np.array([r[2] for r in rows], dtype=float),
        directions=np.array([r[3] for r in rows], dtype=float),
        iso=np.array([iso_of(*r[3]) for r in rows], dtype=float),
        wavelengths=WAVELENGTHS.copy(), spectra=np.array([r[4] for r in rows]),
        quality=np.zeros(n, dtype=int), flagged=np.zeros(n, dtype=bool),
        flag_reasons=np.array([""] * n, dtype=object),
        reference_ids=np.array([r[5] for r in rows], dtype=np.int64),
        dark_ids=np.array([r[6] for r in rows], dtype=np.int64),
        integration_ms=np.full(n, 100), labels=np.array([""] * n, dtype=object))


class FakeInterpolationClient:
    """Answers interpolate / interpolate_batch from a ReadingSet with the NumPy octant reference
    (BRDF only), shaped as brdf_client's results, in place of a live brdfd."""

    def __init__(self, readings, white_reflectance=WHITE):
        self.samples = readings.of_kind("sample")
        self.spectra = np.array([reading_spectrum(readings, i, "brdf", white_reflectance)
                                 for i in self.samples.ids])

    def _one(self, direction, mirror_phi=False, reciprocity=False):
        octant = octant_reference.Octant(self.samples.iso, self.spectra, None, mirror_phi,
                                         reciprocity)
        status, rows, weights, spectrum = octant.evaluate(np.asarray(direction, float))
        # (With symmetries the daemon reports the mirrored copy's position; the figures only
        # draw vertices of answers without them.)
        vertices = [Vertex(int(self.samples.ids[r]), self.samples.iso[r].copy(), float(w))
                    for r, w in zip(rows, weights)]
        return InterpolationResult(
            query=np.asarray(direction, float), axes=("theta_i", "theta_o", "phi"),
            status=status, method="octant", quantity="brdf", wavelengths=WAVELENGTHS.copy(),
            spectrum=np.zeros(0) if spectrum is None else np.asarray(spectrum),
            vertices=vertices, detail="")

    def interpolate(self, session_id, theta_i, theta_o, phi, method="octant", **options):
        del session_id, method
        return self._one((theta_i, theta_o, phi), options.get("mirror_phi", False),
                         options.get("reciprocity", False))

    def interpolate_batch(self, session_id, directions, method="octant", quantity="brdf",
                          mirror_phi=False, reciprocity=False, **_):
        del session_id, method, quantity
        return InterpolationBatch([self._one(d, mirror_phi, reciprocity) for d in directions])
