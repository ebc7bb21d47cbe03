#!/usr/bin/env python3
"""Helpers for check_interp.sh: write query / lattice CSVs, and compare brdf-interp's --explain
output with the independent NumPy octant method (octant_reference.py) or with scipy's
LinearNDInterpolator (Delaunay through Qhull). Prints one summary line per comparison and exits
1 if anything differs beyond the tolerance."""
import argparse
import csv
import sys

import numpy as np

import octant_reference

TOLERANCE = 1e-9
COORDS = {3: ["theta_i", "theta_o", "phi"], 4: ["theta_i", "phi_i", "theta_o", "phi_o"]}


def read_samples(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    d = 4 if len(header) > 1 and header[1] == "phi_i" else 3
    data = np.array([[float(x) for x in r] for r in rows[1:] if r], dtype=float)
    return d, data[:, :d], data[:, d:]


def read_output(path, d):
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        wl = [c for c in reader.fieldnames[d + 1:] if not (c[0] in "vw" and c[1:].isdigit()) and c != "detail"]
        vcols = sorted((c for c in reader.fieldnames if c[0] == "v" and c[1:].isdigit()), key=lambda c: int(c[1:]))
        out = []
        for r in reader:
            q = np.array([float(r[c]) for c in COORDS[d]])
            status = r["status"]
            if status == "ok":
                spectrum = np.array([float(r[c]) for c in wl])
                verts = [int(r[c]) for c in vcols if r[c] != ""]
                weights = [float(r["w" + c[1:]]) for c in vcols if r[c] != ""]
            else:
                spectrum, verts, weights = None, [], []
            out.append((q, status, verts, weights, spectrum))
    return out


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow([repr(float(x)) for x in r])


def cmd_queries(a):
    rng = np.random.default_rng(a.seed)
    lo = np.array([float(x) for x in a.lo.split(",")])
    hi = np.array([float(x) for x in a.hi.split(",")])
    q = lo + (hi - lo) * rng.random((a.n, lo.size))
    if a.at_samples:
        _, pts, _ = read_samples(a.at_samples)
        pick = pts[rng.integers(0, len(pts), a.at_samples_n)].copy()
        # Half of them exactly at a sample, half sharing one coordinate with another sample
        # (on its splitting plane).
        other = pts[rng.integers(0, len(pts), a.at_samples_n)]
        axis = rng.integers(0, lo.size, a.at_samples_n)
        half = np.arange(a.at_samples_n) % 2 == 1
        pick[half, axis[half]] = other[half, axis[half]]
        q = np.vstack([q, pick])
    write_csv(a.out, COORDS[lo.size], q)


def cmd_lattice(a):
    g = np.arange(a.size, dtype=float)
    pts = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T
    rng = np.random.default_rng(a.seed)
    pts = pts[rng.permutation(len(pts))]
    spectra = np.stack([0.3 + 0.01 * b + (0.002 * b - 0.1) * pts[:, 0] + 0.003 * pts[:, 1] - 0.0005 * b * pts[:, 2]
                        for b in range(5)], axis=1)
    write_csv(a.samples, COORDS[3] + ["400", "500", "600", "700", "750"], np.hstack([pts, spectra]))
    q = 0.5 * rng.integers(-1, 2 * a.size + 1, (a.n, 3))
    write_csv(a.queries, COORDS[3], q)


def cmd_octant(a):
    d, pts, spectra = read_samples(a.samples)
    scale = [float(x) for x in a.scale.split(",")] if a.scale else None
    ref = octant_reference.Octant(pts, spectra, scale, a.mirror_phi, a.reciprocity)
    rows = read_output(a.output, d)
    counts, bad, max_w, max_s = {}, 0, 0.0, 0.0
    for i, (q, status, verts, weights, spectrum) in enumerate(rows):
        r_status, r_verts, r_weights, r_spectrum = ref.evaluate(q)
        counts[status] = counts.get(status, 0) + 1
        problem = None
        if status != r_status:
            problem = f"status {status} vs {r_status}"
        elif status == "ok":
            if verts != [int(v) for v in r_verts]:
                problem = f"vertices {verts} vs {list(r_verts)}"
            else:
                dw = np.max(np.abs(np.array(weights) - np.array(r_weights)))
                ds = np.max(np.abs(spectrum - r_spectrum))
                max_w, max_s = max(max_w, dw), max(max_s, ds)
                if dw > TOLERANCE or ds > TOLERANCE:
                    problem = f"weights differ by {dw:.3g}, spectrum by {ds:.3g}"
        if problem:
            bad += 1
            if bad <= 5:
                print(f"  query {i} {q.tolist()}: {problem}", file=sys.stderr)
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    print(f"{a.label}: {len(rows)} queries ({summary}); mismatches {bad}; "
          f"max |Δweight| {max_w:.2g}, max |Δspectrum| {max_s:.2g}")
    return 1 if bad else 0


def cmd_delaunay(a):
    from scipy.interpolate import LinearNDInterpolator
    d, pts, spectra = read_samples(a.samples)
    interp = LinearNDInterpolator(pts, spectra)
    tri = interp.tri
    rows = read_output(a.output, d)
    qs = np.array([r[0] for r in rows])
    values = interp(qs)
    simplex = tri.find_simplex(qs)
    counts, bad, vert_diff, max_s = {}, 0, 0, 0.0
    for i, (q, status, verts, weights, spectrum) in enumerate(rows):
        counts[status] = counts.get(status, 0) + 1
        inside = simplex[i] >= 0
        problem = None
        if (status == "ok") != inside:
            problem = f"status {status} vs scipy {'inside' if inside else 'outside'}"
        elif inside:
            ds = np.max(np.abs(spectrum - values[i]))
            max_s = max(max_s, ds)
            if ds > TOLERANCE:
                problem = f"spectrum differs by {ds:.3g}"
            if sorted(verts) != sorted(tri.simplices[simplex[i]].tolist()):
                vert_diff += 1  # a different simplex with the same value: query on a shared face
        if problem:
            bad += 1
            if bad <= 5:
                print(f"  query {i} {q.tolist()}: {problem}", file=sys.stderr)
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    print(f"{a.label}: {len(rows)} queries ({summary}); mismatches {bad}; "
          f"other simplex (same value) {vert_diff}; max |Δspectrum| {max_s:.2g}")
    return 1 if bad else 0


def main():
    p = argparse.ArgumentParser(description=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    q = sub.add_parser("queries")
    q.add_argument("--n", type=int, required=True)
    q.add_argument("--lo", required=True)
    q.add_argument("--hi", required=True)
    q.add_argument("--seed", type=int, default=1)
    q.add_argument("--at-samples")
    q.add_argument("--at-samples-n", type=int, default=0)
    q.add_argument("--out", required=True)
    lat = sub.add_parser("lattice")
    lat.add_argument("--size", type=int, default=8)
    lat.add_argument("--n", type=int, default=2000)
    lat.add_argument("--seed", type=int, default=1)
    lat.add_argument("--samples", required=True)
    lat.add_argument("--queries", required=True)
    for name in ("octant", "delaunay"):
        c = sub.add_parser(name)
        c.add_argument("--label", required=True)
        c.add_argument("--samples", required=True)
        c.add_argument("--output", required=True)
        c.add_argument("--scale")
        c.add_argument("--mirror-phi", action="store_true")
        c.add_argument("--reciprocity", action="store_true")
    a = p.parse_args()
    return {"queries": cmd_queries, "lattice": cmd_lattice, "octant": cmd_octant,
            "delaunay": cmd_delaunay}[a.cmd](a) or 0


if __name__ == "__main__":
    sys.exit(main())
