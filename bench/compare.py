#!/usr/bin/env python3
"""Our interpolation against scipy, side by side, in one run (bench/run.sh calls this).

Both sides read the same CSV files: the samples written by `brdf-interp synth` and the queries
written here, in the same order. Our side is bench_interp_driver, a long-running process this
script drives over a pipe; every repetition of a measurement runs scipy, then ours, then the next
one, so both see the same machine load. Figures are medians over the repetitions.

  data sets   rig      the paper's rig grid (2,153 points), queries = random rig poses
                       (α ∈ [0,70], β ∈ [-175,180], δ ∈ [0,146.25], converted like the grid)
              random   50,000 uniform points in [0,90)×[0,90)×[0,360), queries uniform there
              random401  the same points and queries, 401-band spectra (1 nm; when random401.csv
                       is in the work folder)
              aniso4d  4D anisotropic set (θi, φi, θo, φo), uniform in [0,90)×[0,360)×[0,90)×[0,360)
  orders      random   as generated
              sorted   the same queries sorted along a Morton (Z-order) curve
  methods     scipy LinearNDInterpolator (Qhull Delaunay; one call on the whole array)
              scipy cKDTree nearest (query + gather of the spectra)
              ours: octant (spectra only / full answers with provenance), nearest, Delaunay

Only Debian's python3 with numpy and scipy is needed.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from scipy.interpolate import LinearNDInterpolator
from scipy.spatial import cKDTree


def log(msg):
    print(msg, file=sys.stderr, flush=True)


class Driver:
    def __init__(self, path):
        self.p = subprocess.Popen([path], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def ask(self, line):
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        reply = json.loads(self.p.stdout.readline())
        if "error" in reply:
            raise RuntimeError(f"driver: {line}: {reply['error']}")
        return reply

    def close(self):
        self.p.stdin.write("quit\n")
        self.p.stdin.flush()
        self.p.wait()


def write_queries(path, q, dims):
    header = "theta_i,theta_o,phi" if dims == 3 else "theta_i,phi_i,theta_o,phi_o"
    np.savetxt(path, q, delimiter=",", header=header, comments="", fmt="%.17g")


def rig_pose_queries(n, seed):
    """Random rig poses converted to (θi, θo, φ) as the rig grid is (geometry.md)."""
    rng = np.random.default_rng(seed)
    out = []
    while sum(len(o) for o in out) < n:
        m = 2 * n
        a = np.radians(rng.uniform(0, 70, m))
        b = np.radians(rng.uniform(-175, 180, m))
        dl = np.radians(rng.uniform(0, 146.25, m))
        ci = np.cos(a) * np.cos(b)
        co = np.cos(a) * np.cos(b - dl)
        ti = np.degrees(np.arccos(np.clip(ci, -1, 1)))
        to = np.degrees(np.arccos(np.clip(co, -1, 1)))
        with np.errstate(divide="ignore", invalid="ignore"):
            c = (np.cos(dl) - ci * co) / (np.sin(np.radians(ti)) * np.sin(np.radians(to)))
        phi = np.where((ti > 1e-7) & (to > 1e-7), np.degrees(np.arccos(np.clip(c, -1, 1))), 0.0)
        keep = (ti <= 89.999) & (to <= 89.999)
        out.append(np.stack([ti, to, phi], 1)[keep])
    return np.concatenate(out)[:n]


def box_queries(n, hi, seed):
    rng = np.random.default_rng(seed)
    return rng.random((n, len(hi))) * np.array(hi, dtype=float)


def morton_order(q, bits=10):
    """Indices that sort the queries along a Morton (Z-order) curve over their bounding box."""
    lo, hi = q.min(0), q.max(0)
    cells = ((q - lo) / np.where(hi > lo, hi - lo, 1) * ((1 << bits) - 1)).astype(np.uint64)
    code = np.zeros(len(q), dtype=np.uint64)
    d = q.shape[1]
    for bit in range(bits):
        for j in range(d):
            code |= ((cells[:, j] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(bit * d + j)
    return np.argsort(code, kind="stable")


def load_samples(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    d = 4 if len(header) > 1 and header[1] == "phi_i" else 3
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return d, np.ascontiguousarray(data[:, :d]), np.ascontiguousarray(data[:, d:])


def timed(fn):
    w0, c0 = time.perf_counter(), time.process_time()
    result = fn()
    return result, time.perf_counter() - w0, time.process_time() - c0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--driver", required=True)
    ap.add_argument("--work", required=True, help="folder with rig.csv, random.csv, aniso4d.csv")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--queries", type=int, default=50000)
    ap.add_argument("--queries-4d", type=int, default=20000)
    ap.add_argument("--json", help="write every measurement here")
    args = ap.parse_args()

    load_start = os.getloadavg()
    sets = [
        ("rig", os.path.join(args.work, "rig.csv"), lambda n: rig_pose_queries(n, 101)),
        ("random", os.path.join(args.work, "random.csv"), lambda n: box_queries(n, [90, 90, 360], 102)),
        ("aniso4d", os.path.join(args.work, "aniso4d.csv"),
         lambda n: box_queries(n, [90, 360, 90, 360], 103)),
    ]
    # The same 50,000 points and queries as `random` with 401-band spectra (1 nm, a CS-2000's
    # grid), beside the 101-band case: what a 4× longer spectrum costs each side.
    random401 = os.path.join(args.work, "random401.csv")
    if os.path.exists(random401):
        sets.insert(2, ("random401", random401, lambda n: box_queries(n, [90, 90, 360], 102)))
    drv = Driver(args.driver)
    results = {"load_start": load_start, "sets": {}, "runs": [], "checks": [], "grid": []}
    rows = []  # (set, order, method, median q/s, median cpu µs/query, failed fraction, ref)

    for name, path, make_queries in sets:
        d, pts, vals = load_samples(path)
        n_q = args.queries if d == 3 else args.queries_4d
        q = make_queries(n_q)
        orders = {"random": q, "sorted": q[morton_order(q)]}
        qpaths = {}
        for order, qq in orders.items():
            qpaths[order] = os.path.join(args.work, f"q_{name}_{order}.csv")
            write_queries(qpaths[order], qq, d)
            # Read back what the driver reads, so both sides use the very same doubles.
            orders[order] = np.loadtxt(qpaths[order], delimiter=",", skiprows=1, ndmin=2)
        log(f"[{name}] {len(pts)} points, {d}D, {vals.shape[1]} bands; {n_q} queries")
        info = drv.ask(f"samples {name} {path}")
        lnd, lnd_build_s, _ = timed(lambda: LinearNDInterpolator(pts, vals))
        kdt, kdt_build_s, _ = timed(lambda: cKDTree(pts))
        results["sets"][name] = {"points": len(pts), "dims": d, "bands": vals.shape[1], "queries": n_q,
                                 "ours_build_s": info["build_s"],
                                 "scipy_build_s": {"LinearNDInterpolator": lnd_build_s, "cKDTree": kdt_build_s}}
        for order in orders:
            drv.ask(f"queries {name}_{order} {qpaths[order]}")

        for order, qq in orders.items():
            qn = f"{name}_{order}"
            meas = {k: [] for k in ["scipy_lnd", "scipy_kdt", "octant", "octant_full", "nearest", "delaunay"]}
            failed = {}
            for rep in range(args.reps):
                out, w, c = timed(lambda: lnd(qq))
                meas["scipy_lnd"].append((w, c))
                failed["scipy_lnd"] = float(np.isnan(out[:, 0]).mean())
                r = drv.ask(f"run {name} {qn} octant spectrum")
                meas["octant"].append((r["wall_s"], r["cpu_s"]))
                failed["octant"] = 1 - r["ok"] / r["n"]

                def nearest():
                    _, idx = kdt.query(qq)
                    return vals[idx]
                _, w, c = timed(nearest)
                meas["scipy_kdt"].append((w, c))
                r = drv.ask(f"run {name} {qn} nearest spectrum")
                meas["nearest"].append((r["wall_s"], r["cpu_s"]))
                failed["nearest"] = 1 - r["ok"] / r["n"]
                r = drv.ask(f"run {name} {qn} octant evaluate")
                meas["octant_full"].append((r["wall_s"], r["cpu_s"]))
                failed["octant_full"] = 1 - r["ok"] / r["n"]
                if "delaunay" in info["build_s"]:
                    r = drv.ask(f"run {name} {qn} delaunay spectrum")
                    meas["delaunay"].append((r["wall_s"], r["cpu_s"]))
                    failed["delaunay"] = 1 - r["ok"] / r["n"]
            n = len(qq)
            for method, vals_ in meas.items():
                if not vals_:
                    continue
                walls = [v[0] for v in vals_]
                cpus = [v[1] for v in vals_]
                results["runs"].append({"set": name, "order": order, "method": method, "n": n,
                                        "wall_s": walls, "cpu_s": cpus, "failed": failed.get(method)})
                rows.append((name, order, method, n / statistics.median(walls),
                             1e6 * statistics.median(cpus) / n, failed.get(method)))
            log(f"[{name}/{order}] done")

        # Octant answers against the O(N) reference on the same queries (status, vertices,
        # weights, spectra, detail: all bit for bit).
        chk = drv.ask(f"check {name} {name}_random 2")
        chk["set"] = name
        results["checks"].append(chk)
        log(f"[{name}] check: {chk['mismatches']} mismatches of {chk['n']}")

    # The rendering-scale grid from the 50,000-point set.
    grid = {}
    for threads in (1, 2):
        g = drv.ask(f"grid random {threads} 90 90 180 360 3")
        grid[threads] = g
        results["grid"].append(g)
        log(f"[grid] {threads} thread(s): {g['wall_s']}")
    gc = drv.ask("gridcheck random 97 2")
    results["gridcheck"] = gc
    drv.close()
    results["load_end"] = os.getloadavg()
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)

    # The table.
    names = {"scipy_lnd": "scipy LinearNDInterpolator", "scipy_kdt": "scipy cKDTree nearest",
             "octant": "ours octant (spectra)", "octant_full": "ours octant (full answers)",
             "nearest": "ours nearest (spectra)", "delaunay": "ours Delaunay (spectra)"}
    ref_of = {"octant": "scipy_lnd", "octant_full": "scipy_lnd", "delaunay": "scipy_lnd",
              "nearest": "scipy_kdt"}
    by = {(r[0], r[1], r[2]): r for r in rows}
    print()
    print(f"Our interpolation vs scipy {__import__('scipy').__version__}: single thread, 101 bands "
          f"(random401: 401), "
          f"median of {args.reps} interleaved repetitions (wall clock)")
    print(f"load average at start {load_start[0]:.2f} {load_start[1]:.2f} {load_start[2]:.2f}, "
          f"at end {results['load_end'][0]:.2f} {results['load_end'][1]:.2f} {results['load_end'][2]:.2f}"
          f" (2 cores)")
    hdr = f"{'data set':<27} {'query order':<12} {'method':<28} {'queries/s':>11} {'CPU µs/q':>9} {'failed':>7} {'× scipy':>8}"
    print(hdr)
    print("-" * len(hdr))
    for name, _, _ in sets:
        info = results["sets"][name]
        label = f"{name} N={info['points']:,} {info['dims']}D {info['bands']}b"
        for order in ("random", "sorted"):
            for method in ["scipy_lnd", "octant", "octant_full", "delaunay", "scipy_kdt", "nearest"]:
                r = by.get((name, order, method))
                if r is None:
                    continue
                ratio = ""
                if method in ref_of:
                    ref = by[(name, order, ref_of[method])]
                    ratio = f"{r[3] / ref[3]:.1f}×"
                fail = "" if r[5] is None else f"{100 * r[5]:.2f}%"
                print(f"{label:<27} {order:<12} {names[method]:<28} {r[3]:>11,.0f} {r[4]:>9.2f} {fail:>7} {ratio:>8}")
        print()
    print("Index build (s): " + "; ".join(
        f"{n}: ours octant {s['ours_build_s']['octant']:.3f}, nearest {s['ours_build_s']['nearest']:.3f}"
        + (f", Delaunay {s['ours_build_s']['delaunay']:.3f}" if "delaunay" in s["ours_build_s"] else "")
        + f" | scipy LinearND {s['scipy_build_s']['LinearNDInterpolator']:.3f}, cKDTree {s['scipy_build_s']['cKDTree']:.3f}"
        for n, s in results["sets"].items()))
    print()
    print("Octant answers vs the O(N) reference (status, vertices, weights, spectrum, detail; bit for bit):")
    for c in results["checks"]:
        print(f"  {c['set']:<8} {c['n']:>7} queries: {c['mismatches']} mismatches "
              f"(ok {c['ok']}, empty octant {c['empty_octant']}, no enclosing simplex {c['no_enclosing_simplex']})")
    print(f"  grid     {gc['checked']:>7} grid points (every 97th): {gc['mismatches']} mismatches")
    print()
    print("Regular grid 90×90×180 (θi, θo every 1°, φ every 2° over [0,360)) from the 50,000-point set,"
          " octant, spectra into one 1,458,000 × 101 array (median of 3):")
    for threads, g in grid.items():
        print(f"  {threads} thread(s): {statistics.median(g['wall_s']):.2f} s wall "
              f"({g['n'] / statistics.median(g['wall_s']):,.0f} queries/s), {statistics.median(g['cpu_s']):.2f} s CPU, "
              f"ok {g['ok']:,} of {g['n']:,}")
    bad = sum(c["mismatches"] for c in results["checks"]) + gc["mismatches"]
    if "random401" in results["sets"]:
        print("401 bands beside 101 (the random set's points and queries, random order; CPU µs a query,"
              " which the machine's load moves less than wall clock):")
        for method in ("octant", "octant_full", "delaunay", "scipy_lnd"):
            a, b = by.get(("random", "random", method)), by.get(("random401", "random", method))
            if a and b:
                print(f"  {names[method]:<28} 101 bands {a[4]:6.2f} µs, 401 bands {b[4]:6.2f} µs "
                      f"({b[4] / a[4]:.2f}×); queries/s {a[3]:,.0f} → {b[3]:,.0f}")

    # The targets, as measured here. Wall-clock ratios follow the machine's load; the CPU
    # ratio (CPU time per query, scipy's over ours) is shown beside them.
    print()
    print("× scipy: our queries/s over scipy's on the same data, queries and order (octant and Delaunay"
          " against LinearNDInterpolator, nearest against cKDTree).")
    print("Targets (issue 6):")
    for name in ("rig", "random", "random401"):
        ours, ref = by.get((name, "random", "octant")), by.get((name, "random", "scipy_lnd"))
        if ours is None or ref is None:
            continue
        ratio, cpu_ratio = ours[3] / ref[3], ref[4] / ours[4]
        print(f"  octant, 1 thread, random order, {name:<9} >= 10× scipy: {ratio:5.1f}× wall, "
              f"{cpu_ratio:5.1f}× CPU  {'met' if ratio >= 10 else 'NOT met'}")
    checks_ok = bad == 0
    print(f"  octant answers identical to the O(N) reference: {'met' if checks_ok else 'NOT met'}"
          f" ({bad} mismatches)")
    if 2 in grid:
        g2 = statistics.median(grid[2]["wall_s"])
        print(f"  90×90×180 grid from 50,000 points on 2 threads < 5 s: {g2:.2f} s wall "
              f"({statistics.median(grid[2]['cpu_s']):.2f} s CPU)  {'met' if g2 < 5 else 'NOT met'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
