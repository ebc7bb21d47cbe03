"""Figure 8 of the paper: the spectrum interpolated at a direction between samples (solid) with
the spectra of the readings it blends (dotted: the vertices of the enclosing tetrahedron). With
non-negative barycentric weights the solid curve stays between the dotted ones at every band.

    python3 -m brdf_client.figures.fig8 --address HOST:PORT --token T --session ID --out DIR
"""

from typing import Any, List, Optional
import sys

import numpy as np

from . import _common
from ..spectra import vertex_spectra

VERTEX_COLORS = ("#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2")


def blend_mismatch(result, spectra):
    """Largest relative difference between the daemon's spectrum and Σ weight · vertex spectrum
    (0 when the vertex spectra are exactly what the daemon blended)."""
    if not result.ok or len(spectra) == 0:
        return 0.0
    blended = result.weights @ spectra
    scale = np.max(np.abs(result.spectrum)) or 1.0
    return float(np.max(np.abs(blended - result.spectrum)) / scale)


def plot(data: Any, path: str) -> str:
    """Draws Figure 8 from SessionData into the PNG file `path`."""
    plt = _common.pyplot()
    result = data.query
    fig, ax = plt.subplots(figsize=(9, 5.6))
    spectra = np.zeros((0, len(result.wavelengths)))
    if result.vertices:
        spectra = vertex_spectra(data.readings, result, data.white_reflectance)
        for k, (v, s) in enumerate(zip(result.vertices, spectra)):
            ax.plot(data.readings.wavelengths, s, linestyle=":", linewidth=1.8,
                    color=VERTEX_COLORS[k % len(VERTEX_COLORS)],
                    label=f"reading {v.reading_id} at {_common.fmt_direction(v.coords)}, "
                          f"weight {v.weight:.3f}")
    if result.ok:
        ax.plot(result.wavelengths, result.spectrum, color="black", linewidth=2.2,
                label=f"interpolated ({result.method}) at {_common.fmt_direction(result.query)}")
    else:
        ax.text(0.5, 0.5, f"no spectrum at {_common.fmt_direction(result.query)}: "
                          f"{result.status}\n{result.detail}", transform=ax.transAxes,
                ha="center", va="center", color=_common.QUERY_COLOR)
    ax.set_xlabel("wavelength λ (nm)")
    ax.set_ylabel(_common.UNIT_LABELS.get(result.quantity, result.quantity))
    if len(result.wavelengths):
        ax.set_xlim(result.wavelengths[0], result.wavelengths[-1])
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.set_title(f"Figure 8 — interpolated spectrum (solid) and its vertex spectra (dotted)\n"
                 f"{data.title}", fontsize=11)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=8, framealpha=0.9)
    fig.tight_layout()
    mismatch = blend_mismatch(result, spectra)
    if mismatch > 1e-3:
        print(f"fig8: the vertex spectra recomputed with ρw = {data.white_reflectance:g} differ "
              f"from the daemon's blend by {100 * mismatch:.2g} %; pass --white-reflectance with "
              "the daemon's [sample] white_reflectance", file=sys.stderr)
    return _common.save(fig, path)


def main(argv: Optional[List[str]] = None) -> int:
    args = _common.parser(__doc__.splitlines()[0]).parse_args(argv)
    client, session_id = _common.connect(args)
    with client:
        data = _common.gather(client, session_id, args.query, args.method, args.white_reflectance)
    print(plot(data, f"{args.out}/fig8.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
