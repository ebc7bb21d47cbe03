#!/usr/bin/env python3
"""scipy's side of bench/product/run.sh: the same job as brdfd's, from the same data.

  grid  READINGS_CSV OUT_NPY DTI DTO DPHI   resample the session's BRDF samples on the grid of
        cell centres (θi, θo over [0, 90), φ over [0, 180]) with LinearNDInterpolator, slice by
        slice of θi into a .npy of shape (nθi, nθo, nφ, bands), as `brdfctl export <id> grid` does
  batch READINGS_CSV DIRECTIONS_CSV OUT_RAW  LinearNDInterpolator at the directions (one call),
        raw doubles n × bands, as InterpolateBatch answers them
  points READINGS_CSV POINTS_F64 VALUES_F64  the same samples as raw doubles (n × 3 directions,
        n × bands values), the input of bench_grid_search (grid_search.cc); no interpolation

Both print one JSON line: the wall seconds of each part and in total (reading the CSV included:
brdfd reads its SQLite database too). The samples are the readings CSV's sample rows, at (θi, θo,
φ) reduced as brdfd reduces them.
"""
import csv
import json
import sys
import time

import numpy as np
from scipy.interpolate import LinearNDInterpolator


EPS = 1e-9  # kNormalThetaEpsilonDeg


def load(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    head = rows[0]
    col = {name: i for i, name in enumerate(head)}
    bands = [i for i, name in enumerate(head) if name.replace(".", "").isdigit()]
    kind = col.get("kind")
    body = [r for r in rows[1:] if kind is None or r[kind] == "sample"]
    ang = np.array([[float(r[col[k]]) for k in ("theta_i_deg", "phi_i_deg", "theta_o_deg",
                                                  "phi_o_deg")] for r in body])
    vals = np.array([[float(r[i]) for i in bands] for r in body])
    # (θi, θo, φ) as brdfd reduces a reading (core/geometry.cc, ToIsotropic): φ = |φo − φi|
    # folded into [0, 180], 0 when either direction is at the normal.
    phi = np.mod(np.abs(ang[:, 3] - ang[:, 1]), 360.0)
    phi = np.where(phi > 180.0, 360.0 - phi, phi)
    normal = (np.abs(ang[:, 0]) < EPS) | (np.abs(ang[:, 2]) < EPS)
    pts = np.column_stack([ang[:, 0], ang[:, 2], np.where(normal, 0.0, phi)])
    return pts, vals


def main():
    what = sys.argv[1]
    t0 = time.perf_counter()
    pts, vals = load(sys.argv[2])
    t1 = time.perf_counter()
    if what == "points":
        np.ascontiguousarray(pts, dtype="<f8").tofile(sys.argv[3])
        np.ascontiguousarray(vals, dtype="<f8").tofile(sys.argv[4])
        print(json.dumps({"what": what, "samples": len(pts), "bands": vals.shape[1]}))
        return
    interp = LinearNDInterpolator(pts, vals)
    t2 = time.perf_counter()
    out = {"what": what, "samples": len(pts), "bands": vals.shape[1], "load_s": t1 - t0,
           "build_s": t2 - t1}
    if what == "grid":
        dti, dto, dphi = (float(x) for x in sys.argv[4:7])
        ti = (np.arange(round(90 / dti)) + 0.5) * dti
        to = (np.arange(round(90 / dto)) + 0.5) * dto
        ph = (np.arange(round(180 / dphi)) + 0.5) * dphi
        grid = np.lib.format.open_memmap(sys.argv[3], mode="w+", dtype="<f8",
                                         shape=(len(ti), len(to), len(ph), vals.shape[1]))
        o, p = np.meshgrid(to, ph, indexing="ij")
        for i, t in enumerate(ti):
            q = np.column_stack([np.full(o.size, t), o.ravel(), p.ravel()])
            grid[i] = interp(q).reshape(len(to), len(ph), vals.shape[1])
        grid.flush()
        del grid
        out["cells"] = len(ti) * len(to) * len(ph)
    else:
        q = np.loadtxt(sys.argv[3], delimiter=",", skiprows=1)
        res = interp(q)
        res.tofile(sys.argv[4])
        out["directions"] = len(q)
        out["ok"] = int(np.count_nonzero(~np.isnan(res[:, 0])))
    t3 = time.perf_counter()
    out["interp_s"] = t3 - t2
    out["total_s"] = t3 - t0
    print(json.dumps(out))


if __name__ == "__main__":
    main()
