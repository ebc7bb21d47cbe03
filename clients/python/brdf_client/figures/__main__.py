"""Writes fig7.png, fig8.png and polar.png of a session into --out, and prints the interpolation
behind Figures 7 and 8 (the query, its vertices with their weights, the spectrum).

    python3 -m brdf_client.figures --address HOST:PORT --token T --session ID --out DIR
"""

from typing import Any, List, Optional
import sys

import numpy as np

from . import _common, fig7, fig8, polar
from .. import names
from ..spectra import vertex_spectra

SHOWN_NM = (400, 450, 500, 550, 600, 650, 700, 750)


def describe(data: Any) -> str:
    """The query's answer as text: status, vertices and weights, and a few bands of the
    interpolated spectrum next to its vertex spectra."""
    r = data.query
    lines = [f"interpolation ({r.method}, {r.quantity} in {r.unit}) at "
             f"{_common.fmt_direction(r.query)}: {r.status}"]
    if r.detail:
        lines.append(f"  {r.detail}")
    for v in r.vertices:
        lines.append(f"  vertex reading {v.reading_id:>6} at {_common.fmt_direction(v.coords)}"
                     f"  weight {v.weight:.4f}")
    if r.ok:
        spectra: Any = vertex_spectra(data.readings, r, data.white_reflectance) if r.vertices else []
        header = "  λ (nm)  interpolated" + "".join(f"  v{v.reading_id:<9}" for v in r.vertices)
        lines.append(header)
        for nm in SHOWN_NM:
            if r.wavelengths[0] <= nm <= r.wavelengths[-1]:
                row = f"  {nm:>6}  {r.at(nm):12.6f}"
                row += "".join(f"  {np.interp(nm, r.wavelengths, s):10.6f}" for s in spectra)
                lines.append(row)
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    p = _common.parser("Writes the paper's Figures 7 and 8 and a polar plot of a session.")
    p.add_argument("--wavelength", type=float, default=550.0,
                   help="wavelength of the polar plot, nm (default 550)")
    p.add_argument("--theta-i", type=float, nargs="+", default=None,
                   help="incidence angles of the polar plot, degrees (default: up to 4 with "
                        "in-plane readings)")
    p.add_argument("--polar-method", default="delaunay", choices=sorted(names.METHODS),
                   help="interpolation method of the polar plot (default delaunay: it reaches "
                        "the plane of incidence, the edge of φ's range, where octants are empty)")
    args = p.parse_args(argv)
    client, session_id = _common.connect(args)
    with client:
        data = _common.gather(client, session_id, args.query, args.method, args.white_reflectance)
        pdata = polar.gather(client, session_id, data.readings, args.wavelength, args.theta_i,
                             args.polar_method, True, args.white_reflectance, data.title)
    print(describe(data))
    for path in (fig7.plot(data, f"{args.out}/fig7.png"), fig8.plot(data, f"{args.out}/fig8.png"),
                 polar.plot(pdata, f"{args.out}/polar.png")):
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
