"""What the three figures share: matplotlib without a display, the command line, the session's
data, and the choice of a query direction between the samples (queries.py, re-exported here).
"""

import argparse
import dataclasses
import os
from typing import Any

import matplotlib

matplotlib.use("Agg")  # files only: works without a display (ssh, CI, systemd)
from matplotlib import pyplot as plt  # noqa: E402  pylint: disable=wrong-import-position

from .. import names  # noqa: E402  pylint: disable=wrong-import-position
from ..client import BrdfClient  # noqa: E402  pylint: disable=wrong-import-position
from ..queries import candidate_queries, pick_query  # noqa: E402,F401  pylint: disable=wrong-import-position

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
