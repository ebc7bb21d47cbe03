"""A direction worth showing: strictly between a session's samples, where the blend visibly
mixes its readings (Figures 7 and 8, the notebook). No plotting here.

    q = pick_query(brdf, sid, data.of_kind("sample"), readings=data)   # InterpolationResult
"""

from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from .spectra import vertex_spectra

if TYPE_CHECKING:  # pragma: no cover
    from .client import BrdfClient
    from .interpolation import InterpolationResult
    from .readings import ReadingSet


def candidate_queries(iso: Any, limit: int = 400) -> np.ndarray:
    """Directions between measured points, most interior first.

    For the `limit` distinct points nearest the centroid of all points, the centroid of that point
    and its 3 nearest distinct neighbours (degrees, rounded to 0.1°), nearest the data's centre
    first: there every octant around the candidate holds readings.
    """
    pts = np.unique(np.round(np.asarray(iso, float), 6), axis=0)
    if len(pts) < 4:
        return np.zeros((0, 3))
    centre = pts.mean(axis=0)
    seeds = pts[np.argsort(np.linalg.norm(pts - centre, axis=1), kind="stable")[:limit]]
    d = np.linalg.norm(seeds[:, None, :] - pts[None, :, :], axis=2)  # limit × N
    near = np.argsort(d, axis=1, kind="stable")[:, :4]  # the seed itself and its 3 nearest
    cands = np.round(pts[near].mean(axis=1), 1)
    _, first = np.unique(cands, axis=0, return_index=True)
    return cands[np.sort(first)]


def _spread(readings: "ReadingSet", result: "InterpolationResult",
            white_reflectance: float) -> float:
    """How much the vertex spectra of `result` differ: mean over bands of (max − min) / max."""
    spectra = vertex_spectra(readings, result, white_reflectance)
    top = np.max(np.abs(spectra), axis=0)
    return float(np.mean((spectra.max(axis=0) - spectra.min(axis=0)) / np.where(top > 0, top, 1)))


def pick_query(client: "BrdfClient", session_id: str, samples: "ReadingSet",
               method: str = "octant", min_weight: float = 0.1,
               readings: Optional["ReadingSet"] = None,
               white_reflectance: float = 0.99) -> "InterpolationResult":
    """An InterpolationResult at a direction strictly between samples.

    Tries candidate_queries in one InterpolateBatch. Among the OK answers whose every vertex
    weighs at least `min_weight` (the blend visibly mixes its readings), keeps the first — or,
    given `readings` (all kinds, for the vertex spectra), the one whose vertex spectra differ most,
    which makes Figure 8 telling (near a highlight rather than on a flat diffuse stretch). Falls
    back to the first OK answer; RuntimeError when none is OK (too few readings: give --query).
    """
    cands = candidate_queries(samples.iso)
    if len(cands) == 0:
        raise RuntimeError(f"session {session_id} has {len(samples)} sample readings: too few to "
                           "interpolate between; run a larger plan or give --query")
    batch = client.interpolate_batch(session_id, cands, method=method)
    ok = [r for r in batch if r.ok]
    if not ok:
        statuses = ", ".join(sorted(set(batch.statuses)))
        raise RuntimeError(f"no direction between the samples of session {session_id} could be "
                           f"interpolated with {method} (statuses: {statuses}); give --query "
                           "θi θo φ, or try --method delaunay")
    interior = [r for r in ok if len(r.weights) and r.weights.min() >= min_weight]
    if not interior:
        return ok[0]
    if readings is None:
        return interior[0]
    spreads = [_spread(readings, r, white_reflectance) for r in interior]
    return interior[int(np.argmax(spreads))]
