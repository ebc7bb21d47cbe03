"""Figure 7 of the paper: the sample points (a) in the rig's (α, β, δ), normalised to their
maxima as the paper does, and (b) in (θi, θo, φ), with a query point (red) and the tetrahedron
of readings that encloses it (from the interpolation's provenance).

    python3 -m brdf_client.figures.fig7 --address HOST:PORT --token T --session ID --out DIR
"""

from typing import Any, List, Optional
import sys

import numpy as np
from matplotlib.ticker import MaxNLocator

from . import _common

EDGES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))  # the 6 edges of a tetrahedron
QUERY_COLOR = _common.QUERY_COLOR
EDGE_COLOR = _common.EDGE_COLOR


def _normalised(values):
    """values / max |values| (the paper's X, Y, Z); the max for the axis label."""
    top = float(np.max(np.abs(values))) if len(values) else 0.0
    return (values / top if top > 0 else values), top


def plot(data: Any, path: str) -> str:
    """Draws Figure 7 from SessionData into the PNG file `path`."""
    plt = _common.pyplot()
    samples = data.samples
    result = data.query
    vertex_rows = [samples.index_of(i) for i in result.vertex_ids if i in samples.ids]

    fig = plt.figure(figsize=(13, 6.2))
    fig.suptitle(f"Figure 7 — sample points of {data.title} ({len(samples)} sample readings)",
                 fontsize=13)

    # (a) the rig's coordinates, normalised as in the paper.
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    x, a_max = _normalised(samples.poses[:, 0])
    y, b_max = _normalised(samples.poses[:, 1])
    z, d_max = _normalised(samples.poses[:, 3])
    ax.scatter(x, y, z, s=6, c="#1f77b4", depthshade=False, label="sample readings")
    if vertex_rows:
        ax.scatter(x[vertex_rows], y[vertex_rows], z[vertex_rows], s=60, facecolors="none",
                   edgecolors=EDGE_COLOR, linewidths=1.5, depthshade=False,
                   label="readings of the tetrahedron")
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(5))
    ax.set_xlabel(f"X = α / {a_max:.1f}°")
    ax.set_ylabel(f"Y = β / {b_max:.1f}°")
    ax.set_zlabel(f"Z = δ / {d_max:.1f}°")
    ax.set_title("(a) sample points in (α, β, δ), normalised to their maxima", fontsize=11)
    ax.legend(loc="upper left", fontsize=8)
    ax.view_init(elev=22, azim=-60)

    # (b) the same readings in the sample's frame, with the query and its tetrahedron.
    ax = fig.add_subplot(1, 2, 2, projection="3d")
    iso = samples.iso
    ax.scatter(iso[:, 0], iso[:, 1], iso[:, 2], s=5, c="#1f77b4", alpha=0.45, depthshade=False,
               label="sample readings")
    q = result.query
    if result.vertices and result.vertex_coords.shape[1] == 3:
        v = result.vertex_coords
        for i, j in EDGES:
            ax.plot(*zip(v[i], v[j]), color=EDGE_COLOR, linewidth=1.6)
        ax.scatter(v[:, 0], v[:, 1], v[:, 2], s=40, c=EDGE_COLOR, depthshade=False,
                   label=f"enclosing tetrahedron ({result.method})")
    ax.scatter([q[0]], [q[1]], [q[2]], s=90, c=QUERY_COLOR, edgecolors="white", depthshade=False,
               label=f"query: {_common.fmt_direction(q)}")
    ax.set_xlabel("θi (degrees)")
    ax.set_ylabel("θo (degrees)")
    ax.set_zlabel("φ (degrees)")
    ax.set_xlim(0, 90)
    ax.set_ylim(0, 90)
    ax.set_zlim(0, 180)
    status = "" if result.ok else f" — interpolation failed: {result.status}"
    ax.set_title(f"(b) the same points in (θi, θo, φ){status}", fontsize=11)
    ax.legend(loc="upper left", fontsize=8)
    ax.view_init(elev=22, azim=-60)

    fig.subplots_adjust(left=0.02, right=0.97, bottom=0.04, top=0.9, wspace=0.08)
    return _common.save(fig, path)


def main(argv: Optional[List[str]] = None) -> int:
    args = _common.parser(__doc__.splitlines()[0]).parse_args(argv)
    client, session_id = _common.connect(args)
    with client:
        data = _common.gather(client, session_id, args.query, args.method, args.white_reflectance)
    print(plot(data, f"{args.out}/fig7.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
