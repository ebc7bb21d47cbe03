"""A polar plot of the BRDF at one wavelength in the plane of incidence, for a few θi.

Angles are the outgoing polar angle θo from the sample normal (straight up): to the right the
specular side (φ = 180°), to the left the retro side (φ = 0°, towards the lamp). Lines are
interpolated by the daemon along θo every 1°; markers are the session's readings that lie in the
plane of incidence at that θi, turned into BRDF from their raw spectra. Gaps are directions the
method could not fill (an empty octant near the edge of the data).

    python3 -m brdf_client.figures.polar --address HOST:PORT --token T --session ID --out DIR
"""

from typing import Any, List, Optional
import dataclasses
import sys

import numpy as np

from . import _common
from ..spectra import reading_spectrum

CURVE_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")
THETA_O_STEP = 1.0
THETA_O_MAX = 85.0
# Readings count as taken at a curve's θi within this (stage readings are quantised to counts).
MATCH_DEG = 0.1


@dataclasses.dataclass
class PolarCurve:
    """The BRDF at one θi along the plane of incidence.

    theta_o: (n,) signed θo, degrees: > 0 specular side (φ 180°), < 0 retro side (φ 0°).
    values:  (n,) BRDF at the wavelength, sr⁻¹ (NaN where not interpolated).
    measured_theta_o, measured_values: the in-plane readings at this θi, the same way.
    """

    theta_i: float
    theta_o: np.ndarray
    values: np.ndarray
    measured_theta_o: np.ndarray
    measured_values: np.ndarray


@dataclasses.dataclass
class PolarData:
    """What the polar plot draws."""

    title: str
    wavelength_nm: float
    method: str
    symmetries: bool
    curves: list


def in_plane(iso, tol=0.05):
    """(n,) bool: readings in the plane of incidence (φ = 0° or 180°; also θi or θo = 0)."""
    phi = iso[:, 2]
    return (np.abs(phi) < tol) | (np.abs(phi - 180.0) < tol)


def signed_theta_o(iso):
    """θo with the side as its sign: + specular side (φ 180°), − retro side (φ 0°)."""
    return np.where(np.abs(iso[:, 2] - 180.0) < 0.05, iso[:, 1], -iso[:, 1])


def default_thetas(samples, count=4, max_theta=65.0):
    """Up to `count` incidence angles (degrees, > 0) with the most in-plane readings, spread out.

    A θi qualifies when the plane of incidence holds readings at 3 or more distinct θo there
    (the sample-rotation grid's α = 0 rows, θi = |β|); the δ = 0 readings alone (θo = θi) do not.
    """
    # Stage readings sit within a motor count (~0.04°) of the plan's angles: group by 0.1°.
    iso = np.round(samples.iso[in_plane(samples.iso)], 1)
    candidates = []
    for theta_i in np.unique(iso[:, 0]):
        distinct_theta_o = len(np.unique(signed_theta_o(iso[iso[:, 0] == theta_i])))
        if 0 < theta_i <= max_theta and distinct_theta_o >= 3:
            candidates.append(float(theta_i))
    if not candidates:
        return [15.0, 30.0, 45.0, 60.0]
    if len(candidates) <= count:
        return candidates
    picks = np.round(np.linspace(0, len(candidates) - 1, count)).astype(int)
    return [candidates[i] for i in picks]


def queries_for(theta_i):
    """(directions (n, 3), signed θo (n,)) along the plane of incidence at `theta_i`."""
    steps = np.arange(0.0, THETA_O_MAX + 1e-9, THETA_O_STEP)
    if theta_i == 0:  # at normal incidence φ is undefined (0 by convention): one half, mirrored
        dirs = np.array([(0.0, t, 0.0) for t in steps])
        return np.concatenate([dirs[::-1], dirs[1:]]), np.concatenate([-steps[::-1], steps[1:]])
    retro = [(theta_i, t, 0.0) for t in steps[::-1]]  # θo = 0 belongs here (φ = 0 by convention)
    spec = [(theta_i, t, 180.0) for t in steps[1:]]
    return np.array(retro + spec), np.concatenate([-steps[::-1], steps[1:]])


def gather(client, session_id, readings, wavelength_nm=550.0, thetas=None, method="delaunay",
           symmetries=True, white_reflectance=0.99, title=""):
    """Interpolates the curves and collects the in-plane readings (PolarData).

    method: "delaunay" by default: the plane of incidence is the edge of φ's range (0 and 180),
    where the octant method finds its "−" or "+" octants empty; Delaunay fills it up to the data's
    hull.
    symmetries: use the isotropic sample's exact symmetries (φ mirror, reciprocity θi ↔ θo),
    which extend the data across φ = 0 and θi = θo.
    """
    samples = readings.of_kind("sample")
    thetas = list(thetas) if thetas else default_thetas(samples)
    curves = []
    plane = np.flatnonzero(in_plane(samples.iso))
    for theta_i in thetas:
        dirs, signed = queries_for(theta_i)
        batch = client.interpolate_batch(session_id, dirs, method=method, quantity="brdf",
                                         mirror_phi=symmetries, reciprocity=symmetries)
        rows = plane[np.abs(samples.iso[plane, 0] - theta_i) < MATCH_DEG]
        m_theta = signed_theta_o(samples.iso[rows])
        m_values = np.array([
            np.interp(wavelength_nm, readings.wavelengths,
                      reading_spectrum(readings, samples.ids[r], "brdf", white_reflectance))
            for r in rows])
        if theta_i == 0 and len(rows):  # symmetric: show each reading on both sides
            m_theta = np.concatenate([m_theta, -m_theta])
            m_values = np.concatenate([m_values, m_values])
        curves.append(PolarCurve(float(theta_i), signed, batch.at(wavelength_nm), m_theta,
                                 m_values))
    return PolarData(title, float(wavelength_nm), method, symmetries, curves)


def plot(pdata: Any, path: str) -> str:
    """Draws the polar plot into the PNG file `path`."""
    plt = _common.pyplot()
    from matplotlib.lines import Line2D  # pylint: disable=import-outside-toplevel
    from matplotlib.ticker import MaxNLocator  # pylint: disable=import-outside-toplevel
    fig = plt.figure(figsize=(9.5, 7.5))
    ax = fig.add_subplot(1, 1, 1, projection="polar")
    ax.set_theta_zero_location("N")  # the sample normal points up
    ax.set_theta_direction(-1)       # positive θo (specular side) to the right
    ax.set_thetamin(-90)
    ax.set_thetamax(90)
    handles = []
    for k, c in enumerate(pdata.curves):
        color = CURVE_COLORS[k % len(CURVE_COLORS)]
        ax.plot(np.radians(c.theta_o), c.values, color=color, linewidth=1.8)
        if len(c.measured_theta_o):
            ax.plot(np.radians(c.measured_theta_o), c.measured_values, linestyle="none",
                    marker="o", markersize=5, color=color, markeredgecolor="black",
                    markeredgewidth=0.6)
        handles.append(Line2D([], [], color=color, linewidth=1.8, marker="o", markersize=5,
                              markeredgecolor="black", markeredgewidth=0.6,
                              label=f"θi = {c.theta_i:g}°"))
    sym = ";\nφ mirror, reciprocity" if pdata.symmetries else ""
    handles.append(Line2D([], [], color="gray", linewidth=1.8,
                          label=f"interpolated every {THETA_O_STEP:g}°\n({pdata.method}{sym})"))
    handles.append(Line2D([], [], color="gray", linestyle="none", marker="o", markersize=5,
                          markeredgecolor="black", markeredgewidth=0.6,
                          label="readings in the plane"))
    ax.set_thetagrids(range(-90, 91, 15), [f"{abs(a)}°" for a in range(-90, 91, 15)])
    ax.set_rlabel_position(-90)  # radial ticks along the retro-side baseline
    ax.set_ylim(bottom=0)
    ax.yaxis.set_major_locator(MaxNLocator(5))
    rmax = ax.get_rmax()
    ax.annotate("BRDF (sr$^{-1}$)", xy=(np.radians(-90), rmax / 2), xytext=(0, -24),
                textcoords="offset points", ha="center", va="top", fontsize=10)
    ax.annotate("specular side →", xy=(np.radians(90), rmax), xytext=(0, -10),
                textcoords="offset points", ha="right", va="top", fontsize=10)
    fig.suptitle(f"BRDF at {pdata.wavelength_nm:g} nm in the plane of incidence — "
                 f"{pdata.title}\nangle: outgoing direction θo from the sample normal (up); "
                 "left: retro side (φ = 0°, towards the lamp), right: specular side (φ = 180°)",
                 fontsize=10)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.04, 1.0), fontsize=9,
              framealpha=0.9, title="incidence θi", title_fontsize=9)
    ax.text(1.04, 0.12, "gaps in a line: directions the\nmethod cannot reach from the\n"
                       "measured data", ha="left", va="bottom", fontsize=8, color="#555555",
            transform=ax.transAxes)
    return _common.save(fig, path, tight=True)


def main(argv: Optional[List[str]] = None) -> int:
    p = _common.parser(__doc__.splitlines()[0])
    p.set_defaults(method="delaunay")
    p.add_argument("--wavelength", type=float, default=550.0, help="nm (default 550)")
    p.add_argument("--theta-i", type=float, nargs="+", default=None,
                   help="incidence angles, degrees (default: up to 4 with in-plane readings)")
    p.add_argument("--no-symmetries", action="store_true",
                   help="do not use the φ mirror and reciprocity when interpolating")
    args = p.parse_args(argv)
    client, session_id = _common.connect(args)
    with client:
        session = client.get_session(session_id)
        readings = client.load_readings(session_id)
        title = f"session {session.session_id} — {session.name}"
        pdata = gather(client, session_id, readings, args.wavelength, args.theta_i, args.method,
                       not args.no_symmetries, args.white_reflectance, title)
    print(plot(pdata, f"{args.out}/polar.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
