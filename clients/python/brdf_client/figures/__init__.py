"""The paper's figures from a live session, as PNG files (matplotlib, Agg backend).

  fig7   sample points in (α, β, δ) and in (θi, θo, φ), a query and its enclosing tetrahedron;
  fig8   the interpolated spectrum (solid) with the spectra of its vertices (dotted);
  polar  the BRDF at one wavelength in the plane of incidence, for a few θi.

    python3 -m brdf_client.figures --address HOST:PORT --token T --session ID --out DIR

Each module has plot(data, path), which draws from plain data (so figures can be made from any
ReadingSet and InterpolationResult), and main() for the command line.
"""

from . import fig7, fig8, polar
from ._common import SessionData, candidate_queries, gather, pick_query

__all__ = ["SessionData", "candidate_queries", "fig7", "fig8", "gather", "pick_query", "polar"]
