#!/usr/bin/env python3
"""Reads an RGL material file (.bsdf) with brdf_client.rgl (clients/python; the evaluation of
Mitsuba 3's measured BSDF and pbrt-v4's MeasuredBxDF, see docs/rgl-format.md) and prints its
fields, or f at directions, or draws its figures (brdf_client.figures.rgl).

Usage:
  rgl_read.py FILE.bsdf                              fields, shapes, dtypes, description
  rgl_read.py FILE.bsdf --at ti,pi,to,po ...         f (sr^-1) at directions (degrees): 610, 550,
                                                     465 nm (R, G, B for an RGB file)
  rgl_read.py FILE.bsdf --sphere OUT.png [--grid G.npy] [--slices OUT.png]
Exit status 0 on success, 1 on a malformed file.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../clients/python"))
from brdf_client.rgl import Material  # noqa: E402
from brdf_client.figures import rgl as figures  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("file")
    ap.add_argument("--at", nargs="*", default=[])
    ap.add_argument("--sphere")
    ap.add_argument("--grid")
    ap.add_argument("--slices")
    a = ap.parse_args()
    try:
        m = Material(a.file)
    except (ValueError, KeyError) as e:
        print(f"rgl_read: {a.file}: {e}", file=sys.stderr)
        return 1
    for k, v in m.fields.items():
        print(f"{k}: {v.dtype} {list(v.shape)}")
    print("description:", bytes(m.fields["description"]).decode("utf8", "replace"))
    bands = figures.band_indices(m)
    for s in a.at:
        ti, pi, to, po = (np.radians(float(x)) for x in s.split(","))
        f = m.brdf(np.array([ti]), np.array([pi]), np.array([to]), np.array([po]))[0]
        print(s, " ".join(f"{f[b]:.6g}" for b in bands))
    if a.slices:
        figures.plot_slices(m, a.slices)
    if a.sphere:
        diff = figures.plot_sphere(m, a.sphere, a.grid)
        if diff is not None:
            print(f"sphere: mean |file - interpolant| / mean = {100 * diff:.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
