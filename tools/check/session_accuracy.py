#!/usr/bin/env python3
"""How close brdfd's interpolation of a recorded session comes to the simulator's known BRDF.

Run against a brdfd that recorded a session on brdf-sim (docs/interpolation.md, "Bivariate trend",
shows how: brdf-sim --glossy and examples/plans/paper-grid.json). It
  - exports the session's readings (brdfctl export ID csv) and builds scipy's LinearNDInterpolator
    on the sample readings' (θi, θo, φ), independently of brdfd;
  - draws random rig poses (α in [0°, 70°], β in [−175°, 180°], δ in [0°, 146.25°], seeded) and
    asks brdfd through the Python client (interpolate_batch) for every method, coordinates and
    trend;
  - takes the truth from `brdf-sim truth` at each query;
and prints per row the RMS error over the queries every row answered (as a percentage of the mean
truth there), its ratio to scipy's, and the error at the specular-peak query (42.5°, 42.5°, 177.5°)
at 552 nm.

Environment: BRDF_ADDRESS and BRDF_TOKEN (as brdfctl); PYTHONPATH with clients/python;
BRDF_PY_STUBS or a build tree the client finds.
Usage: session_accuracy.py SESSION_ID --build BUILD_DIR [--queries N] [--seed S] [--sample glossy|paint]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy.interpolate import LinearNDInterpolator

PEAK = (42.5, 42.5, 177.5)


def sample_readings(csv_path):
    """(θi, θo, φ) and BRDF spectra of the SAMPLE rows of a readings CSV, and the wavelengths."""
    rows = [r for r in csv.reader(open(csv_path, newline="")) if r and not r[0].startswith("#")]
    head = rows[0]
    col = {name: head.index(name) for name in
           ("kind", "theta_i_deg", "theta_o_deg", "phi_i_deg", "phi_o_deg")}
    bands = [i for i, h in enumerate(head) if h.replace(".", "", 1).isdigit()]
    points, values = [], []
    for r in rows[1:]:
        if r[col["kind"]] != "sample":
            continue
        phi = abs(float(r[col["phi_o_deg"]]) - float(r[col["phi_i_deg"]])) % 360.0
        points.append([float(r[col["theta_i_deg"]]), float(r[col["theta_o_deg"]]),
                       min(phi, 360.0 - phi)])
        values.append([float(r[i]) for i in bands])
    return np.array(points), np.array(values), [float(head[i]) for i in bands]


def rig_pose_queries(n, seed):
    rng = np.random.default_rng(seed)
    r = math.pi / 180
    out = []
    while len(out) < n:
        a, b, d = 70 * rng.random() * r, (-175 + 355 * rng.random()) * r, 146.25 * rng.random() * r
        ci, co = math.cos(a) * math.cos(b), math.cos(a) * math.cos(b - d)
        ti, to = math.acos(ci) / r, math.acos(co) / r
        if ti > 89.999 or to > 89.999 or ti < 1e-6 or to < 1e-6:
            continue
        c = (math.cos(d) - ci * co) / (math.sin(ti * r) * math.sin(to * r))
        out.append((ti, to, math.acos(max(-1.0, min(1.0, c))) / r))
    return np.array(out)


def truth_at(build, queries, sample):
    flag = ["--glossy"] if sample == "glossy" else []
    out = []
    for t in queries:
        text = subprocess.run(
            [os.path.join(build, "tools/brdf-sim/brdf-sim"), "truth", "--json", *flag,
             "--theta-i", repr(t[0]), "--theta-o", repr(t[1]), "--phi", repr(t[2])],
            check=True, capture_output=True, text=True).stdout
        out.append(json.loads(text)["brdf"])
    return np.array(out)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("session")
    p.add_argument("--build", required=True, help="the build directory (brdfctl, brdf-sim)")
    p.add_argument("--queries", type=int, default=400)
    p.add_argument("--seed", type=int, default=19)
    p.add_argument("--sample", choices=("glossy", "paint"), default="glossy",
                   help="the sample brdf-sim had mounted")
    a = p.parse_args()
    from brdf_client import BrdfClient

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "readings.csv")
        subprocess.run([os.path.join(a.build, "tools/brdfctl/brdfctl"), "export", a.session, "csv",
                        "-o", path, "--no-progress"], check=True, capture_output=True)
        points, values, wavelengths = sample_readings(path)
    # The band nearest 550 nm, the later one on a tie (552 nm on the PR-650's grid, as brdf-interp).
    band = min(range(len(wavelengths)), key=lambda i: (abs(wavelengths[i] - 550.0), -wavelengths[i]))
    queries = np.vstack([rig_pose_queries(a.queries, a.seed), [PEAK]])
    truth = truth_at(a.build, queries, a.sample)
    print(f"session {a.session}: {len(points)} sample readings; {a.queries} rig poses (seed "
          f"{a.seed}); truth: brdf-sim truth{' --glossy' if a.sample == 'glossy' else ''}")

    rows = {"scipy LinearNDInterpolator, (θi, θo, φ)": LinearNDInterpolator(points, values)(queries)}
    client = BrdfClient(os.environ["BRDF_ADDRESS"], token=os.environ.get("BRDF_TOKEN"))
    for method in ("delaunay", "octant", "nearest"):
        for coordinates in ("incidence", "half-diff"):
            for trend in ("none", "bivariate"):
                got = client.interpolate_batch(a.session, queries, method=method,
                                               coordinates=coordinates, trend=trend)
                rows[f"brdfd {method}, {coordinates}, trend {trend}"] = got.spectra
    common = np.ones(len(queries), bool)
    for v in rows.values():
        common &= np.isfinite(v).all(axis=1)
    use = common[:-1]
    print(f"{use.sum()} queries answered by every row; peak {PEAK} at {wavelengths[band]:g} nm")
    print("| row | RMS | × scipy | peak |\n|---|---|---|---|")
    scipy_rms = None
    for name, v in rows.items():
        d = v[:-1][use] - truth[:-1][use]
        rms = math.sqrt(float((d ** 2).mean())) / float(truth[:-1][use].mean())
        scipy_rms = scipy_rms or rms
        peak = (v[-1, band] - truth[-1, band]) / truth[-1, band]
        peak_text = "failed" if not np.isfinite(peak) else f"{100 * peak:+.2f} %"
        print(f"| {name} | {100 * rms:.2f} % | {rms / scipy_rms:.2f} | {peak_text} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
