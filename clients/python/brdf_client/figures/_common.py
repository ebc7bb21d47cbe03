"""What the three figures share: matplotlib without a display, the command line, the session's
data, and the choice of a query direction between the samples.
"""

import argparse
import dataclasses
import os
from typing import Any

import matplotlib

matplotlib.use("Agg")  # files only: works without a display (ssh, CI, systemd)
from matplotlib import pyplot as plt  # noqa: E402  pylint: disable=wrong-import-position
import numpy as np  # noqa: E402  pylint: disable=wrong-import-position

from .. import names  # noqa: E402  pylint: disable=wrong-import-position
from ..client import BrdfClient  # noqa: E402  pylint: disable=wrong-import-position
from ..spectra import vertex_spectra  # noqa: E402  pylint: disable=wrong-import-position

DPI = 150
# Axis labels with units, in matplotlib's mathtext (renders with any font).
UNIT_LABELS = {
    "brdf": r"BRDF $f$ (sr$^{-1}$)",
    "reflectance": r"reflectance $R = I/I_0$ (ratio)",
    "radiance": r"radiance $I$ (W m$^{-2}$ sr$^{-1}$ nm$^{-1}$)",
}
QUERY_COLOR = "#d62728"
EDGE_COLOR = "#222222"


def pyplot():
    """matplotlib.pyplot, on the Agg backend."""
    return plt


def save(fig, path, tight=False):
    """Writes `fig` as PNG to `path` (creating its directory) and closes it. Returns the path.
    tight: trim the margins to what is drawn (legends placed outside the axes included)."""
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fig.savefig(path, dpi=DPI, format="png", bbox_inches="tight" if tight else None,
                pad_inches=0.25)
    plt.close(fig)
    return path


def fmt_direction(coords):
    """(θi, θo, φ) → 'θi 30.0°, θo 40.0°, φ 160.0°' (or the four-angle form)."""
    c = [float(x) for x in coords]
    if len(c) == 3:
        return f"θi {c[0]:.1f}°, θo {c[1]:.1f}°, φ {c[2]:.1f}°"
    return f"θi {c[0]:.1f}°, φi {c[1]:.1f}°, θo {c[2]:.1f}°, φo {c[3]:.1f}°"


@dataclasses.dataclass
class SessionData:
    """A session's readings and one interpolation between its samples: the figures' input.

    session:   brdf_pb2.Session (name, state, plan).
    readings:  every reading (ReadingSet: samples, references, darks; for the vertex spectra).
    query:     an InterpolationResult at a direction between the samples (with its vertices).
    white_reflectance: ρw used to turn stored readings into BRDF (the daemon's [sample] setting).
    """

    session: Any
    readings: Any
    query: Any
    white_reflectance: float = 0.99

    @property
    def samples(self):
        return self.readings.of_kind("sample")

    @property
    def title(self):
        name = self.session.name if self.session is not None else ""
        sid = self.session.session_id if self.session is not None else ""
        return f"session {sid}" + (f" — {name}" if name else "")


def candidate_queries(iso, limit=400):
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


def _spread(readings, result, white_reflectance):
    """How much the vertex spectra of `result` differ: mean over bands of (max − min) / max."""
    spectra = vertex_spectra(readings, result, white_reflectance)
    top = np.max(np.abs(spectra), axis=0)
    return float(np.mean((spectra.max(axis=0) - spectra.min(axis=0)) / np.where(top > 0, top, 1)))


def pick_query(client, session_id, samples, method="octant", min_weight=0.1, readings=None,
               white_reflectance=0.99):
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


def gather(client: Any, session_id: str, query: Any = None, method: str = "octant",
           white_reflectance: float = 0.99) -> SessionData:
    """Loads what the figures need from a live daemon: the session, all its readings, and an
    interpolation at `query` ((θi, θo, φ), degrees) or at a direction picked between samples."""
    session = client.get_session(session_id)
    readings = client.load_readings(session_id)
    samples = readings.of_kind("sample")
    if query is None:
        result = pick_query(client, session_id, samples, method, readings=readings,
                            white_reflectance=white_reflectance)
    else:
        result = client.interpolate(session_id, *query, method=method)
    return SessionData(session, readings, result, white_reflectance)


def latest_session(client: Any) -> str:
    """The id of the newest COMPLETED session, else the newest one; ValueError when none."""
    done = client.list_sessions(states=["completed"], page_size=1, limit=1)
    if done:
        return done[0].session_id
    every = client.list_sessions(page_size=1, limit=1)
    if every:
        return every[0].session_id
    raise ValueError("the daemon has no sessions yet; submit a plan first (or give --session)")


def parser(description):
    """The command line every figure script takes."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--address", default=os.environ.get("BRDF_ADDRESS", "127.0.0.1:50051"),
                   help="brdfd's address, host:port or unix:/path (default: $BRDF_ADDRESS or "
                        "127.0.0.1:50051)")
    p.add_argument("--token", default=None,
                   help="bearer token (default: $BRDF_TOKEN); an analyst token is enough")
    p.add_argument("--session", default=None,
                   help="session id (default: the newest completed session)")
    p.add_argument("--out", default=".", help="directory for the PNG files (default: .)")
    p.add_argument("--query", nargs=3, type=float, metavar=("THETA_I", "THETA_O", "PHI"),
                   default=None, help="direction to interpolate, degrees (default: one picked "
                                      "between the samples)")
    p.add_argument("--method", default="octant", choices=sorted(names.METHODS),
                   help="interpolation method (default: octant, the paper's)")
    p.add_argument("--white-reflectance", type=float, default=0.99,
                   help="ρw of the white standard, as in the daemon's [sample] white_reflectance "
                        "(default 0.99); used for the vertex spectra")
    p.add_argument("--tls", action="store_true", help="connect over TLS")
    p.add_argument("--ca", default=None, help="PEM file of the CA of the daemon's certificate")
    p.add_argument("--cert", default=None, help="client certificate (PEM), for mutual TLS")
    p.add_argument("--key", default=None, help="client key (PEM), for mutual TLS")
    return p


def connect(args):
    """A BrdfClient from parsed arguments, and the session id to draw."""
    client = BrdfClient(args.address, args.token, tls=args.tls, root_certificates=args.ca,
                        client_certificate=args.cert, client_key=args.key)
    session_id = args.session or latest_session(client)
    return client, session_id
