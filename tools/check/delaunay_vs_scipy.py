#!/usr/bin/env python3
"""Compares brdf-interp --method delaunay with scipy.interpolate.LinearNDInterpolator.

Both triangulate with Qhull ("d Qt Qbb Qc Qz Q12"), so on points in general position (random,
no four cospherical) the Delaunay triangulation is unique and the two must agree: same status
(inside / outside the hull), same vertices, same weights and spectra to rounding. On degenerate
input (the rig's regular grid) the triangulation is not unique and the answers may legitimately
differ, so this script uses random samples only.

It runs by hand (not a unit test): the C++ tests must not need Python.

    tools/check/delaunay_vs_scipy.py [--bin build/tools/brdf-interp/brdf-interp] [--bench]

Prints one line per case and exits 1 when a case disagrees beyond the tolerance. --bench also
times scipy's own queries (random and space-filling-curve order) on 50,000 random 3D points, the
baseline brdfd's throughput target is stated against.
Needs Debian's python3 (numpy, scipy): run it as /usr/bin/python3 if another python3 comes first.
"""
import argparse
import csv
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.interpolate import LinearNDInterpolator
from scipy.spatial import Delaunay

EXTENT = {3: [90.0, 90.0, 360.0], 4: [90.0, 360.0, 90.0, 360.0]}
HEADER = {3: ["theta_i", "theta_o", "phi"], 4: ["theta_i", "phi_i", "theta_o", "phi_o"]}


def cpu_children():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def read_samples(path, dims):
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return data[:, :dims], data[:, dims:]


def write_queries(path, q, dims):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(HEADER[dims])
        for row in q:
            w.writerow([repr(float(v)) for v in row])


def read_output(path, dims, bands):
    """Returns status (bool ok), spectra (nan when not ok), vertices, weights."""
    ok, spectra, verts, weights = [], [], [], []
    k = dims + 1
    with open(path, newline="") as f:
        r = csv.reader(f)
        next(r)
        for row in r:
            good = row[dims] == "ok"
            ok.append(good)
            spec = row[dims + 1:dims + 1 + bands]
            spectra.append([float(v) for v in spec] if good else [np.nan] * bands)
            base = dims + 1 + bands
            verts.append([int(v) for v in row[base:base + k]] if good else [-1] * k)
            weights.append([float(v) for v in row[base + k:base + 2 * k]] if good else [np.nan] * k)
    return np.array(ok), np.array(spectra), np.array(verts), np.array(weights)


def morton_order(q, extent):
    """Query order along a Morton (Z-order) curve: consecutive queries are close."""
    dims = q.shape[1]
    quant = np.clip((q / np.array(extent)) * 65535, 0, 65535).astype(np.uint64)
    key = np.zeros(len(q), dtype=np.uint64)
    for bit in range(15, -1, -1):
        for j in range(dims):
            key = (key << np.uint64(1)) | ((quant[:, j] >> np.uint64(bit)) & np.uint64(1))
    return np.argsort(key, kind="stable")


def compare(binary, work, dims, n, seed, n_queries):
    samples = os.path.join(work, f"s{dims}_{n}_{seed}.csv")
    queries = os.path.join(work, f"q{dims}_{n}_{seed}.csv")
    out = os.path.join(work, f"o{dims}_{n}_{seed}.csv")
    subprocess.run([binary, "synth", "--grid", "random", str(n), "--seed", str(seed), "--dims",
                    str(dims), "-o", samples], check=True, stderr=subprocess.DEVNULL)
    pts, spectra = read_samples(samples, dims)
    rng = np.random.default_rng(seed)
    extent = np.array(EXTENT[dims])
    # Mostly inside the data's box; 5 % a little beyond it; 5 % exactly at samples.
    q = rng.uniform(0, 1, (n_queries, dims)) * extent
    beyond = rng.random(n_queries) < 0.05
    q[beyond] = rng.uniform(-0.05, 1.05, (beyond.sum(), dims)) * extent
    at = rng.random(n_queries) < 0.05
    q[at] = pts[rng.integers(0, n, at.sum())]
    write_queries(queries, q, dims)

    t0 = cpu_children()
    subprocess.run([binary, samples, queries, "--method", "delaunay", "--explain", "-o", out],
                   check=True, stderr=subprocess.DEVNULL)
    t_ours = cpu_children() - t0
    ok, ours, verts, weights = read_output(out, dims, spectra.shape[1])

    t0 = time.process_time()
    tri = Delaunay(pts)
    ref = LinearNDInterpolator(tri, spectra)(q)
    t_scipy = time.process_time() - t0
    simplex = tri.find_simplex(q)
    ref_ok = ~np.isnan(ref[:, 0])

    status_diff = int((ok != ref_ok).sum())
    both = ok & ref_ok
    diff = np.abs(ours[both] - ref[both])
    scale = np.abs(ref[both]).max()
    # Compare the blended vertices with their weights, ignoring vertices of weight ~0: a query on
    # a shared face (e.g. exactly at a sample) lies in several simplices, all correct.
    same_vertices = 0
    weight_diff = 0.0
    for i in np.nonzero(both)[0]:
        theirs = tri.simplices[simplex[i]]
        b = tri.transform[simplex[i], :dims].dot(q[i] - tri.transform[simplex[i], dims])
        their_w = {v: w for v, w in zip(theirs.tolist(), np.append(b, 1 - b.sum())) if w > 1e-9}
        our_w = {v: w for v, w in zip(verts[i].tolist(), weights[i]) if w > 1e-9}
        if our_w.keys() != their_w.keys():
            continue
        same_vertices += 1
        for v, w in our_w.items():
            weight_diff = max(weight_diff, abs(w - their_w[v]))
    line = (f"{dims}D N={n:>6} seed={seed}: {len(q)} queries, outside hull {int((~ok).sum())} "
            f"(scipy {int((~ref_ok).sum())}), status mismatches {status_diff}; "
            f"both ok {int(both.sum())}: max |Δ| {diff.max():.3g} (values up to {scale:.3g}), "
            f"RMS Δ {np.sqrt((diff ** 2).mean()):.3g}, same vertices {same_vertices}/{int(both.sum())}, "
            f"max weight Δ {weight_diff:.3g}; CPU time ours {t_ours:.2f} s (whole process: CSV, "
            f"triangulation, queries), scipy {t_scipy:.2f} s (triangulation, queries)")
    print(line, flush=True)
    # Agreement: statuses equal, spectra to 1e-9 relative, the same blended vertices (weight
    # > 1e-9) with the same weights for all but a handful of queries (a query within 1e-9 of a
    # face can be answered from either side).
    good = status_diff == 0 and diff.max() <= 1e-9 * max(scale, 1.0) and \
        same_vertices >= 0.999 * both.sum() and weight_diff <= 1e-9
    return good


def bench_scipy(n=50000, n_queries=100000, bands=101, seed=1):
    rng = np.random.default_rng(seed)
    extent = EXTENT[3]
    pts = rng.uniform(0, 1, (n, 3)) * extent
    values = rng.uniform(0, 1, (n, bands))
    t0 = time.process_time()
    interp = LinearNDInterpolator(pts, values)
    t_build = time.process_time() - t0
    q = rng.uniform(0, 1, (n_queries, 3)) * extent
    qs = q[morton_order(q, extent)]
    rates = []
    for queries in (q, qs):
        best = 1e30
        for _ in range(3):
            t0 = time.process_time()
            interp(queries)
            best = min(best, time.process_time() - t0)
        rates.append(n_queries / best)
    print(f"scipy LinearNDInterpolator, N={n} random 3D points, {bands} bands: build "
          f"{t_build:.2f} s; {rates[0]:,.0f} queries/s random order, {rates[1]:,.0f} queries/s "
          f"Morton order (CPU time, best of 3, {n_queries} queries)")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--bin", default=os.environ.get(
        "BRDF_INTERP", os.path.join(root, "build", "tools", "brdf-interp", "brdf-interp")))
    p.add_argument("--queries", type=int, default=20000)
    p.add_argument("--bench", action="store_true", help="also time scipy's queries")
    a = p.parse_args()
    if not os.access(a.bin, os.X_OK):
        sys.exit(f"delaunay_vs_scipy: {a.bin} is not an executable; build brdf-interp or pass --bin")
    cases = [(3, 500, 1), (3, 3000, 2), (3, 50000, 3), (4, 500, 4), (4, 3000, 5)]
    all_good = True
    with tempfile.TemporaryDirectory() as work:
        for dims, n, seed in cases:
            all_good &= compare(a.bin, work, dims, n, seed, a.queries)
    if a.bench:
        bench_scipy()
    print("delaunay_vs_scipy:", "agree" if all_good else "DISAGREE")
    return 0 if all_good else 1


if __name__ == "__main__":
    sys.exit(main())
