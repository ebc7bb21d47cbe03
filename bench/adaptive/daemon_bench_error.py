#!/usr/bin/env python3
"""The error of sessions recorded by brdfd against `brdf-sim truth` (issue 38, deliverable 5;
docs/adaptive.md, "The benchmark through the daemon"). daemon_bench.sh runs it once per material,
after that material's sessions are recorded, with brdfd still serving them.

What it measures, for each session given (LABEL=ID), with the same directions for every session:

  err    relative RMS error of the cosine-weighted BRDF f · cos θi · cos θo at --directions random
         direction pairs (lamp and detector each uniform in solid angle with θ ≤ --theta-max,
         azimuths φi, φo uniform; numpy's default_rng(--seed)):
             err = sqrt( Σ ((f̂ − f) cos θi cos θo)² / Σ (f cos θi cos θo)² )
  peak   the same along the specular ridge, the mirror directions θo = θi, φo = φi + 180°, at
         --ridge-points incidences θi evenly in (0, --theta-max) (cell centres), φi = 0: where a
         glossy lobe peaks and the octant method under-reads it;
  retro  the same along the retro-reflection ridge θo = θi, φo = φi (a retro-reflector's peak).

f is the BRDF as the planner judges it: a spectrum's mean over the bands from 400 to 700 nm. f̂ is
the session's octant interpolation by the daemon (InterpolateBatch, method octant, mirror_phi, as
adaptive::JudgeOptions mirrors φ), asked at the isotropic direction (θi, θo, |φo − φi| folded to
0…180°); where the octant method has no answer (an empty octant) the daemon's nearest reading
(method nearest) stands in, and the share of such directions is reported (fb). The truth is
`brdf-sim --material FILE truth` at the four angles (θi, φi, θo, φo): for an anisotropic material
the isotropic interpolant's loss of the azimuth φi is part of the error. The truth is computed once
per material and cached (--truth-cache). --four-angles (sessions of an anisotropic plan): the
daemon is asked at the four angles themselves, φ not mirrored (mirror_phi is for isotropic
sessions).

Prints one JSON object per session on stdout: label, session, err, peak, retro, fallback (share
of the random directions), n (directions), and progress on stderr. --breakdown adds the random
directions' err² split as the offline study's --breakdown splits it (shares adding up to err²): by
the half-vector angle θh (bins 0, 5, 10, 15, 25, 90°), by the lamp–detector angle ψ (bins 0, 5.625,
11.25, 16.875, 22.5, 33.75, 180°), at θi or θo above 75°, and where the octant method had no answer.

    daemon_bench_error.py --address 127.0.0.1:50051 --token T --sim build/tools/brdf-sim/brdf-sim \\
        --material deploy/materials/paint.toml --session grid=1 --session adapt20=3
"""

import argparse
import concurrent.futures
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

from brdf_client import BrdfClient  # noqa: E402  pylint: disable=wrong-import-position

BAND_LO, BAND_HI = 400.0, 700.0  # nm: the planner's scalar BRDF (the engine's NextRound)


def log(message):
    print(f"daemon_bench_error: {message}", file=sys.stderr, flush=True)


def random_directions(count, seed, theta_max):
    """(count, 4) θi, φi, θo, φo in degrees: lamp and detector uniform in solid angle."""
    rng = np.random.default_rng(seed)
    c_min = math.cos(math.radians(theta_max))
    theta = np.degrees(np.arccos(rng.uniform(c_min, 1.0, size=(count, 2))))
    phi = rng.uniform(-180.0, 180.0, size=(count, 2))
    return np.column_stack([theta[:, 0], phi[:, 0], theta[:, 1], phi[:, 1]])


def ridge_directions(points, theta_max, phi_o):
    """(points, 4): θi = θo at cell centres in (0, theta_max), φi = 0, φo = phi_o."""
    t = theta_max * (np.arange(points) + 0.5) / points
    return np.column_stack([t, np.zeros(points), t, np.full(points, float(phi_o))])


def isotropic(d4):
    """(N, 3) θi, θo, φ with φ = |φo − φi| folded to [0, 180]."""
    phi = np.abs((d4[:, 3] - d4[:, 1] + 180.0) % 360.0 - 180.0)
    return np.column_stack([d4[:, 0], d4[:, 2], phi])


def scalar(wavelengths, spectra):
    """The mean over the bands within 400–700 nm of each row of spectra (N, m)."""
    wl = np.asarray(wavelengths, dtype=float)
    band = (wl >= BAND_LO - 1e-9) & (wl <= BAND_HI + 1e-9)
    if not band.any():
        raise RuntimeError(f"no band within {BAND_LO:g}–{BAND_HI:g} nm in {wl[:3]}…")
    return np.asarray(spectra, dtype=float)[:, band].mean(axis=1)


def truth_one(sim, material, d):
    args = [sim, "--material", material, "truth", "--theta-i", repr(float(d[0])), "--phi-i",
            repr(float(d[1])), "--theta-o", repr(float(d[2])), "--phi-o", repr(float(d[3])),
            "--json"]
    done = subprocess.run(args, check=False, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed ({done.returncode}): {done.stderr.strip()}")
    out = json.loads(done.stdout)
    return scalar(out["wavelength_nm"], [out["brdf"]])[0]


def truth_all(sim, material, d4, cache):
    """The truth's scalar BRDF at every row of d4, from the cache when it holds these rows."""
    if cache and os.path.isfile(cache):
        held = np.load(cache)
        if held["directions"].shape == d4.shape and np.array_equal(held["directions"], d4):
            log(f"truth: {len(d4)} directions from {cache}")
            return held["truth"]
    log(f"truth: brdf-sim truth at {len(d4)} directions ({os.path.basename(material)})")
    values = np.empty(len(d4))
    start = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        for i, value in enumerate(pool.map(lambda d: truth_one(sim, material, d), d4)):
            values[i] = value
            if (i + 1) % 5000 == 0:
                log(f"truth: {i + 1}/{len(d4)} ({time.monotonic() - start:.0f} s)")
    if cache:
        np.savez(cache, directions=d4, truth=values)
    return values


def interpolated(client, session, d3, mirror_phi=True):
    """(scalar values, fallback mask): octant (φ mirrored unless told not to), the nearest
    reading where it has no answer. d3: (N, 3) isotropic or (N, 4) four-angle directions."""
    batch = client.interpolate_batch(session, d3, method="octant", mirror_phi=mirror_phi,
                                     progress=False, timeout=900)
    values = np.full(len(d3), np.nan)
    if batch.ok.any():  # none (an empty octant everywhere, a sparse 4D session): all nearest
        values[batch.ok] = scalar(batch.wavelengths, batch.spectra[batch.ok])
    missing = ~batch.ok
    if missing.any():
        near = client.interpolate_batch(session, d3[missing], method="nearest", progress=False,
                                        timeout=900)
        if not near.ok.all():
            raise RuntimeError(f"session {session}: no nearest reading for "
                               f"{int((~near.ok).sum())} directions")
        values[missing] = scalar(near.wavelengths, near.spectra)
    return values, missing


def relative_rms(estimate, truth, d4):
    w = np.cos(np.radians(d4[:, 0])) * np.cos(np.radians(d4[:, 2]))
    return float(np.sqrt(np.sum(((estimate - truth) * w) ** 2) / np.sum((truth * w) ** 2)))


THETA_H_BINS = (0.0, 5.0, 10.0, 15.0, 25.0, 90.001)  # degrees: the offline study's --breakdown
PSI_BINS = (0.0, 5.625, 11.25, 16.875, 22.5, 33.75, 180.001)  # ψ, the lamp–detector angle: the same


def half_angles(d4):
    """(θh, ψ) in degrees of each row (θi, φi, θo, φo): the half vector's angle from the normal
    and the angle between lamp and detector."""
    t = np.radians(d4)
    lamp = np.column_stack([np.sin(t[:, 0]) * np.cos(t[:, 1]), np.sin(t[:, 0]) * np.sin(t[:, 1]),
                            np.cos(t[:, 0])])
    det = np.column_stack([np.sin(t[:, 2]) * np.cos(t[:, 3]), np.sin(t[:, 2]) * np.sin(t[:, 3]),
                           np.cos(t[:, 2])])
    h = lamp + det
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    psi = np.degrees(np.arccos(np.clip(np.sum(lamp * det, axis=1), -1.0, 1.0)))
    return np.degrees(np.arccos(np.clip(h[:, 2], -1.0, 1.0))), psi


def breakdown(estimate, truth, d4, missing):
    """The squared error's shares (adding up to err²) by θh bin, by ψ bin, at θi or θo above 75°,
    and where the octant method had no answer, as the offline study's --breakdown splits them."""
    w = np.cos(np.radians(d4[:, 0])) * np.cos(np.radians(d4[:, 2]))
    e2 = ((estimate - truth) * w) ** 2 / np.sum((truth * w) ** 2)
    theta_h, psi = half_angles(d4)
    bins = np.digitize(theta_h, THETA_H_BINS) - 1
    psi_bins = np.digitize(psi, PSI_BINS) - 1
    return {"by_theta_h": [float(e2[bins == b].sum()) for b in range(len(THETA_H_BINS) - 1)],
            "by_psi": [float(e2[psi_bins == b].sum()) for b in range(len(PSI_BINS) - 1)],
            "grazing": float(e2[np.maximum(d4[:, 0], d4[:, 2]) > 75.0].sum()),
            "unanswered": float(e2[missing].sum())}


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--address", required=True, help="brdfd's gRPC address, host:port")
    p.add_argument("--token", default=os.environ.get("BRDF_TOKEN"), help="a bearer token")
    p.add_argument("--sim", required=True, help="the brdf-sim binary (for `truth`)")
    p.add_argument("--material", required=True, help="the material file the sessions measured")
    p.add_argument("--session", action="append", required=True, metavar="LABEL=ID",
                   help="a session to judge (repeat)")
    p.add_argument("--directions", type=int, default=20000, help="random direction pairs")
    p.add_argument("--ridge-points", type=int, default=400, help="points on each ridge")
    p.add_argument("--seed", type=int, default=20261206, help="the random directions' seed")
    p.add_argument("--theta-max", type=float, default=80.0, help="θi, θo at most, degrees")
    p.add_argument("--truth-cache", default="", help="an .npz file caching the truth")
    p.add_argument("--breakdown", action="store_true",
                   help="add the random directions' err² by θh and ψ bin, at θ > 75° and unanswered")
    p.add_argument("--four-angles", action="store_true",
                   help="anisotropic sessions: ask at (θi, φi, θo, φo), φ not mirrored")
    return p.parse_args()


def main():
    a = parse_args()
    sessions = []
    for item in a.session:
        label, _, sid = item.partition("=")
        if not label or not sid:
            sys.exit(f"daemon_bench_error: --session {item!r} is not LABEL=ID")
        sessions.append((label, sid))
    rand = random_directions(a.directions, a.seed, a.theta_max)
    spec = ridge_directions(a.ridge_points, a.theta_max, 180.0)
    retro = ridge_directions(a.ridge_points, a.theta_max, 0.0)
    every = np.vstack([rand, spec, retro])
    truth = truth_all(a.sim, a.material, every, a.truth_cache)
    parts = {"err": slice(0, len(rand)), "peak": slice(len(rand), len(rand) + len(spec)),
             "retro": slice(len(rand) + len(spec), len(every))}
    with BrdfClient(a.address, a.token) as client:
        for label, sid in sessions:
            start = time.monotonic()
            if a.four_angles:
                values, missing = interpolated(client, sid, every, mirror_phi=False)
            else:
                values, missing = interpolated(client, sid, isotropic(every))
            row = {"label": label, "session": sid, "n": len(rand),
                   "fallback": float(missing[parts["err"]].mean())}
            for name, part in parts.items():
                row[name] = relative_rms(values[part], truth[part], every[part])
            if a.breakdown:
                part = parts["err"]
                row["breakdown"] = breakdown(values[part], truth[part], every[part], missing[part])
            log(f"{label} (session {sid}): err {row['err']:.4f}, peak {row['peak']:.4f}, "
                f"retro {row['retro']:.4f}, fallback {100 * row['fallback']:.1f} % "
                f"({time.monotonic() - start:.1f} s)")
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
