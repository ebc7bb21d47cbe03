#!/usr/bin/env python3
"""Independent reader of MERL .binary BRDF files (NumPy), written from the layout of the MERL
distribution's reader (BRDFRead.cpp): three int32 dims (90, 90, 180), then 3*90*90*180 doubles,
channel-major (all red, then green, then blue); index = phi_d + theta_d*180 + theta_h*180*90 with
the non-linear theta_h index floor(sqrt(theta_h/(pi/2)*90*90)), phi_d folded into [0, pi) by
reciprocity; values multiplied by RED_SCALE 1/1500, GREEN_SCALE 1.15/1500, BLUE_SCALE 1.66/1500;
negative = no data.

Usage:
  merl_read.py FILE.binary                         summary (size, dims, missing cells, ranges)
  merl_read.py FILE.binary --at ti,pi,to,po ...    RGB at directions (degrees)
  merl_read.py FILE.binary --probes PROBES.csv [--tol REL]
      compare with `brdf-export merl --probe ...` output: the file's RGB must equal the merl_*
      columns (to 1e-9 relative), and is reported against the interpolator's interp_* columns
      (within --tol relative, default 0.05, plus 2e-3 absolute: the table holds one value per
      cell).
Exit status 0 when every check passes, 1 otherwise.
"""
import argparse
import csv
import sys

import numpy as np

RES_TH, RES_TD, RES_PD = 90, 90, 180
SCALE = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])


def load(path):
    raw = open(path, "rb").read()
    dims = np.frombuffer(raw[:12], dtype="<i4")
    n = int(np.prod(dims))
    if n != RES_TH * RES_TD * RES_PD:
        raise ValueError(f"dimensions {tuple(dims)} do not match (90, 90, 180)")
    expected = 12 + 3 * 8 * n
    if len(raw) != expected:
        raise ValueError(f"{len(raw)} bytes, expected {expected}")
    data = np.frombuffer(raw[12:], dtype="<f8").reshape(3, RES_TH, RES_TD, RES_PD)
    return dims, data


def rotate(v, axis, angle):
    """Rodrigues' rotation of v about a unit axis (right-handed)."""
    v = np.asarray(v, dtype=float)
    axis = np.asarray(axis, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    return v * c + axis * np.dot(axis, v) * (1 - c) + np.cross(axis, v) * s


def half_diff(ti, pi_, to, po):
    """(theta_h, theta_d, phi_d) in radians from directions in radians."""
    wi = np.array([np.sin(ti) * np.cos(pi_), np.sin(ti) * np.sin(pi_), np.cos(ti)])
    wo = np.array([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)])
    h = wi + wo
    h /= np.linalg.norm(h)
    theta_h = np.arccos(np.clip(h[2], -1, 1))
    phi_h = np.arctan2(h[1], h[0])
    d = rotate(rotate(wi, [0, 0, 1], -phi_h), [0, 1, 0], -theta_h)
    theta_d = np.arccos(np.clip(d[2], -1, 1))
    phi_d = np.arctan2(d[1], d[0])
    return theta_h, theta_d, phi_d


def on_boundary(theta_h, theta_d, phi_d, eps=1e-7):
    """True when a coordinate sits on a cell edge: two correct readers may then pick cells one
    apart through rounding in the last bits (e.g. phi_d = 90 deg exactly when theta_i = theta_o)."""
    args = [theta_d / (np.pi / 2) * RES_TD, (phi_d + (np.pi if phi_d < 0 else 0)) / np.pi * RES_PD]
    if theta_h > 0:
        args.append(np.sqrt(theta_h / (np.pi / 2) * RES_TH * RES_TH))
    return any(abs(a - round(a)) < eps for a in args)


def indices(theta_h, theta_d, phi_d):
    if theta_h <= 0:
        ih = 0
    else:
        ih = int(np.sqrt(theta_h / (np.pi / 2) * RES_TH * RES_TH))
    ih = min(max(ih, 0), RES_TH - 1)
    idd = min(max(int(theta_d / (np.pi / 2) * RES_TD), 0), RES_TD - 1)
    if phi_d < 0:
        phi_d += np.pi
    ip = min(max(int(phi_d / np.pi * RES_PD), 0), RES_PD - 1)
    return ih, idd, ip


def lookup(data, ti_deg, pi_deg, to_deg, po_deg):
    ti, pi_, to, po = np.radians([ti_deg, pi_deg, to_deg, po_deg])
    ih, idd, ip = indices(*half_diff(ti, pi_, to, po))
    return data[:, ih, idd, ip] * SCALE


def summary(path, dims, data):
    missing = data[0] < 0
    print(f"{path}: dims {tuple(int(d) for d in dims)}, {data[0].size} cells per channel")
    print(f"  missing (negative) cells: {int(missing.sum())} "
          f"({100.0 * missing.mean():.1f} %)")
    for c, name in enumerate("RGB"):
        v = data[c][~missing] * SCALE[c]
        if v.size:
            print(f"  {name}: min {v.min():.6g}, median {np.median(v):.6g}, max {v.max():.6g} sr^-1")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("file")
    ap.add_argument("--at", nargs="*", default=[], help="ti,pi,to,po in degrees")
    ap.add_argument("--probes", help="CSV from brdf-export merl --probe")
    ap.add_argument("--tol", type=float, default=0.05)
    args = ap.parse_args()

    try:
        dims, data = load(args.file)
    except (OSError, ValueError) as e:
        print(f"merl_read: {args.file}: {e}", file=sys.stderr)
        return 1
    summary(args.file, dims, data)
    for at in args.at:
        ti, pi_, to, po = (float(x) for x in at.split(","))
        r, g, b = lookup(data, ti, pi_, to, po)
        print(f"  at ({ti}, {pi_}, {to}, {po}): R {r:.9g}  G {g:.9g}  B {b:.9g}")

    ok = True
    if args.probes:
        with open(args.probes, newline="") as f:
            rows = list(csv.DictReader(f))
        worst = 0.0
        for row in rows:
            d = [float(row[k]) for k in ("theta_i", "phi_i", "theta_o", "phi_o")]
            got = lookup(data, *d)
            theirs = np.array([float(row[k]) for k in ("merl_r", "merl_g", "merl_b")])
            if not np.allclose(got, theirs, rtol=1e-9, atol=1e-12):
                hd = half_diff(*np.radians(d))
                if on_boundary(*hd):
                    print(f"  {d} lies on a cell edge: this reader and brdf-export's picked "
                          f"neighbouring cells ({got} vs {theirs}); not an error")
                else:
                    print(f"  MISMATCH at {d}: file {got} vs brdf-export's lookup {theirs}")
                    ok = False
            if row["status"] == "ok":
                interp = np.array([float(row[k]) for k in ("interp_r", "interp_g", "interp_b")])
                rel = np.max(np.abs(got - interp) / (np.abs(interp) + 1e-12))
                worst = max(worst, rel)
                good = np.all(np.abs(got - interp) <= args.tol * np.abs(interp) + 2e-3)
                flag = "ok" if good else "FAR"
                ok = ok and good
                print(f"  {d}: file RGB {np.round(got, 6)}  interpolated {np.round(interp, 6)}"
                      f"  rel {rel:.3g} {flag}")
            else:
                print(f"  {d}: interpolator: {row['status']}; file RGB {np.round(got, 6)}")
        print(f"probes: {len(rows)}, largest relative difference file vs interpolated: {worst:.3g}")
    print("merl_read: " + ("all checks passed" if ok else "CHECKS FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
