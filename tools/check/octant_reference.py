#!/usr/bin/env python3
"""An independent NumPy implementation of Sun & Wang's octant interpolation, written from
docs/interpolation.md (not from the C++), used by check_interp.sh to cross-check
brdf-interp.

The method, as pinned by interpolation.md:
  1. Split space by the axis-aligned planes through the query P into 2^d orthants; a point whose
     coordinate equals P's on an axis is on the "+" side of that axis.
  2. In each orthant take the point nearest to P (Euclidean distance on the scaled coordinates;
     among equally distant points the one recorded first). An empty orthant: status empty_octant.
  3. 3D: label the winners A=(-,-,-) B=(+,-,-) C=(+,+,-) D=(-,+,-) E=(-,-,+) F=(+,-,+)
     G=(+,+,+) H=(-,+,+) (axis order theta_i, theta_o, phi) and try the tetrahedra
     ABCF, ACDH, AEFH, CFGH, ACFH in that order. 4D (theta_i, phi_i, theta_o, phi_o): corners
     indexed by bit pattern (bit j set = "+" on axis j), the 24 Kuhn simplices, one per
     permutation of the axes in lexicographic order, walking from corner 0 to corner 15.
  4. The first simplex that encloses P (all barycentric weights >= -1e-12, whatever its
     orientation; flat simplices skipped) gives the blend: weights clamped at 0 and renormalised,
     spectrum = sum of weight * vertex spectrum. None: no_enclosing_simplex.
Options as in brdf-interp: --scale multiplies each axis; --mirror-phi appends (ti, to, -phi)
copies and --reciprocity (to, ti, phi) copies (both: mirrored, swapped, swapped+mirrored), each
block after all measured samples, so measured samples win ties.

Usage as a library: Octant(points, spectra, scale, mirror_phi, reciprocity).evaluate(q)
-> (status, vertex_rows, weights, spectrum).
"""
import itertools

import numpy as np

LETTER_CORNERS = {"A": 0, "B": 1, "C": 3, "D": 2, "E": 4, "F": 5, "G": 7, "H": 6}
TETRAHEDRA = [[LETTER_CORNERS[c] for c in name] for name in ("ABCF", "ACDH", "AEFH", "CFGH", "ACFH")]


def kuhn_simplices(d):
    out = []
    for perm in itertools.permutations(range(d)):
        corner, path = 0, [0]
        for axis in perm:
            corner |= 1 << axis
            path.append(corner)
        out.append(path)
    return out


ENCLOSING_TOLERANCE = 1e-12
FLAT_RELATIVE_VOLUME = 1e-12


def barycentric(vertices, p):
    """Weights of p in the simplex (rows of `vertices`), or None if flat / outside."""
    edges = (vertices[1:] - vertices[0]).T  # columns are edges
    det = np.linalg.det(edges)
    hadamard = np.prod(np.linalg.norm(edges, axis=0))
    if not abs(det) > FLAT_RELATIVE_VOLUME * hadamard:
        return "flat"
    mu = np.linalg.solve(edges, p - vertices[0])
    lam = np.concatenate([[1.0 - mu.sum()], mu])
    if np.any(lam < -ENCLOSING_TOLERANCE):
        return None
    lam = np.maximum(lam, 0.0)
    return lam / lam.sum()


class Octant:
    def __init__(self, points, spectra, scale=None, mirror_phi=False, reciprocity=False):
        points = np.asarray(points, dtype=float)
        n, d = points.shape
        self.d = d
        blocks = [points]
        if mirror_phi:
            blocks.append(points * np.array([1, 1, -1.0]))
        if reciprocity:
            blocks.append(points[:, [1, 0, 2]])
        if mirror_phi and reciprocity:
            blocks.append(points[:, [1, 0, 2]] * np.array([1, 1, -1.0]))
        self.coords = np.vstack(blocks)
        self.row = np.tile(np.arange(n), len(blocks))
        self.scale = np.ones(d) if scale is None else np.asarray(scale, dtype=float)
        self.scaled = self.coords * self.scale
        self.spectra = np.asarray(spectra, dtype=float)
        self.simplices = TETRAHEDRA if d == 3 else kuhn_simplices(d)
        self.bits = 1 << np.arange(d)

    def evaluate(self, query):
        p = np.asarray(query, dtype=float) * self.scale
        orthant = ((self.scaled >= p) * self.bits).sum(axis=1)
        dist2 = ((self.scaled - p) ** 2).sum(axis=1)
        winners = {}
        for o in range(1 << self.d):
            members = np.flatnonzero(orthant == o)
            if members.size == 0:
                return "empty_octant", [], [], None
            # argmin returns the first of equal minima: the earliest point wins ties.
            winners[o] = members[np.argmin(dist2[members])]
        for simplex in self.simplices:
            ranks = [winners[c] for c in simplex]
            w = barycentric(self.scaled[ranks], p)
            if w is None or isinstance(w, str):
                continue
            rows = self.row[ranks]
            return "ok", list(rows), list(w), w @ self.spectra[rows]
        return "no_enclosing_simplex", [], [], None
