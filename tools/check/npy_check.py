#!/usr/bin/env python3
"""Loads a brdf-export grid (.npy) with NumPy and checks it against its JSON description.

Usage: npy_check.py GRID.npy [--csv GRID.csv]
  - np.load must read it: float64, C order, shape = the JSON's shape (θi, θo, φ, band);
  - every cell is either all NaN or all finite, and the NaN cells are the JSON's nan_cells;
  - with --csv (the same grid exported as CSV): every value equals the CSV's.
Exit status 0 when every check passes, 1 otherwise.
"""
import argparse
import csv
import json
import sys

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("npy")
    ap.add_argument("--csv")
    args = ap.parse_args()
    a = np.load(args.npy)
    desc = json.load(open(args.npy + ".json"))
    ok = True

    def check(cond, what):
        nonlocal ok
        print(("  ok   " if cond else "  FAIL ") + what)
        ok = ok and bool(cond)

    print(f"{args.npy}: dtype {a.dtype}, shape {a.shape}, C order {a.flags['C_CONTIGUOUS']}")
    check(a.dtype == np.float64, "dtype float64")
    check(list(a.shape) == desc["shape"], f"shape {list(a.shape)} == description {desc['shape']}")
    nan = np.isnan(a)
    cell_nan = nan.all(axis=-1)
    check((nan.any(axis=-1) == cell_nan).all(), "each cell is all-NaN or all-finite")
    check(int(cell_nan.sum()) == desc["nan_cells"],
          f"NaN cells {int(cell_nan.sum())} == description {desc['nan_cells']}")
    ax = {k: desc[k] for k in ("theta_i_deg", "theta_o_deg", "phi_deg")}
    print(f"  axes: {ax}, quantity {desc['quantity']} in {desc['unit']}")
    if not cell_nan.all():
        finite = a[~cell_nan]
        print(f"  values: min {finite.min():.6g}, max {finite.max():.6g}")
    if args.csv:
        with open(args.csv, newline="", encoding="utf-8") as f:
            lines = [line for line in f if not line.startswith("#")]
        table = list(csv.reader(lines))
        header, body = table[0], table[1:]
        col = {name: i for i, name in enumerate(header)}
        rows = {n: np.array([float(r[col[n]]) for r in body]) for n in ("theta_i", "theta_o", "phi")}
        spec = np.array([[float(v) for v in r[4:]] for r in body])
        def index(values, axis):
            return np.rint((values - axis["start"]) / axis["step"]).astype(int)
        i = index(rows["theta_i"], ax["theta_i_deg"])
        j = index(rows["theta_o"], ax["theta_o_deg"])
        k = index(rows["phi"], ax["phi_deg"])
        from_npy = a[i, j, k, :]
        same = np.array_equal(np.isnan(from_npy), np.isnan(spec)) and np.array_equal(
            from_npy[~np.isnan(spec)], spec[~np.isnan(spec)])
        check(same, f"{len(body)} CSV rows equal the .npy cells (NaN where the CSV says nan)")
    print("npy_check: " + ("all checks passed" if ok else "CHECKS FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
