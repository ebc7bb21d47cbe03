#!/usr/bin/env python3
"""How long a candidate list per block of grid cells would be (bench/README.md, issue 41).

  block_lists.py POINTS_F64 [BLOCKS]   (POINTS_F64: scipy_side.py points' n × 3 directions)

For blocks of the 1° × 1° × 2° grid's cell centres (θi, θo, φ) of several shapes, at random: per
orthant o, the bound U = the distance from the block's far corner (for o) to the nearest point in
orthant o of every query of the block (a witness); the list = every point within U of the block's
box that can lie in orthant o for some query of it, over the orthants. Such a list holds every
winner of every query of the block (the orthant grid's argument, core/interp/search/
orthant_grid.h). Prints the lists' sizes per shape, and how many blocks had an orthant without a
witness (the data's edges). numpy only, brute force: a study, not the product's code.
"""
import sys

import numpy as np

STEP = np.array([1.0, 1.0, 2.0])
COUNT = np.array([90, 90, 90])


def block_list(points, lo, hi):
    """Size of the block's list, or None when some orthant has no witness."""
    cand = np.zeros(len(points), bool)
    gap = np.maximum(np.maximum(lo - points, points - hi), 0.0)
    mindist2 = np.sum(gap**2, axis=1)
    for o in range(8):
        plus = np.array([(o >> j) & 1 for j in range(3)], bool)
        near = np.where(plus, hi, lo)
        far = np.where(plus, lo, hi)
        witness = np.all(np.where(plus, points >= near, points < near), axis=1)
        if not witness.any():
            return None
        bound2 = np.min(np.sum((points[witness] - far) ** 2, axis=1)) * (1 + 1e-9)
        can = np.all(np.where(plus, points >= lo, points < hi), axis=1)
        cand |= can & (mindist2 <= bound2)
    return int(cand.sum())


def main():
    points = np.fromfile(sys.argv[1]).reshape(-1, 3)
    blocks = int(sys.argv[2]) if len(sys.argv) > 2 else 600
    rng = np.random.default_rng(1)
    for shape in [(1, 1, 1), (2, 2, 2), (1, 2, 4), (1, 1, 8), (2, 2, 4), (4, 4, 4)]:
        shape = np.array(shape)
        sizes, without = [], 0
        for _ in range(blocks):
            first = np.array([rng.integers(0, COUNT[j] - shape[j] + 1) for j in range(3)])
            n = block_list(points, (first + 0.5) * STEP, (first + shape - 0.5) * STEP)
            if n is None:
                without += 1
            else:
                sizes.append(n)
        s = np.array(sizes)
        q = int(np.prod(shape))
        print(f"block {tuple(int(x) for x in shape)} ({q} queries): list mean {s.mean():.1f}, "
              f"median {np.median(s):.0f}, 90th percentile {np.percentile(s, 90):.0f}; "
              f"{s.mean() / q:.1f} per query; {without} of {blocks} blocks without a witness")


if __name__ == "__main__":
    main()
