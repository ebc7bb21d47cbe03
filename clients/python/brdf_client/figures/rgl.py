"""Figures of an RGL material file (.bsdf) read by brdf_client.rgl: its stored tables (luminance
and one wavelength, for four θi slices) and a sphere lit by a distant light rendered from the
file, beside one rendered from the session's interpolant (a `brdf-export grid --nodes` .npy of
the same session, looked up trilinearly).

    python3 -m brdf_client.figures.rgl FILE.bsdf [--grid G.npy] --out DIR
"""

from typing import Any, List, Optional
import argparse
import os
import sys

import numpy as np

from ..rgl import Material

def band_indices(m):
    if m.rgb:
        return [0, 1, 2]
    wl = np.asarray(m.channels)
    return [int(np.argmin(np.abs(wl - x))) for x in (610, 550, 465)]


def sphere_directions(size, light):
    """Per pixel of an orthographic view of a unit sphere: (θi, φi, θo, φo) in a local frame."""
    y, x = np.mgrid[1:-1:size * 1j, -1:1:size * 1j]
    inside = x * x + y * y < 0.999
    n = np.stack([x, y, np.sqrt(np.clip(1 - x * x - y * y, 0, 1))], -1)[inside]
    view = np.array([0, 0, 1.0])
    l = np.asarray(light, float) / np.linalg.norm(light)
    t = np.cross(n, [0, 1.0, 0])
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    b = np.cross(n, t)
    local = lambda w: np.stack([(w * t).sum(-1), (w * b).sum(-1), (w * n).sum(-1)], -1)
    wi, wo = local(np.broadcast_to(l, n.shape)), local(np.broadcast_to(view, n.shape))
    ang = lambda w: (np.arccos(np.clip(w[:, 2], -1, 1)), np.arctan2(w[:, 1], w[:, 0]))
    ti, pi = ang(wi)
    to, po = ang(wo)
    return inside, ti, pi, to, po


def render(inside, f, ti):
    img = np.zeros(inside.shape + (3,))
    lit = np.clip(np.cos(ti), 0, None)[:, None] * f
    img[inside] = lit
    return img


def tonemap(img, peak):
    v = np.clip(img / peak, 0, 1)
    return np.where(v < 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def grid_brdf(grid_path, ti, to, phi, bands):
    """Trilinear lookup in a `brdf-export grid --nodes` .npy (θi, θo, φ, λ), degrees."""
    g = np.load(grid_path, mmap_mode="r")
    axes = [np.linspace(0, 90, g.shape[0]), np.linspace(0, 90, g.shape[1]),
            np.linspace(0, 180, g.shape[2])]
    q = [ti, to, phi]
    idx, w = [], []
    for a, x in zip(axes, q):
        k = np.clip(np.searchsorted(a, x, side="right") - 1, 0, len(a) - 2)
        idx.append(k)
        w.append(np.clip((x - a[k]) / (a[k + 1] - a[k]), 0, 1))
    out = np.zeros((len(ti), len(bands)))
    sub = np.asarray(g[..., bands])
    for c in range(8):
        bits = [(c >> d) & 1 for d in range(3)]
        wt = np.ones(len(ti))
        for d in range(3):
            wt = wt * (w[d] if bits[d] else 1 - w[d])
        v = sub[idx[0] + bits[0], idx[1] + bits[1], idx[2] + bits[2]]
        out += wt[:, None] * np.nan_to_num(v)
    return out


def plot_sphere(m, path, grid=None, size=200):
    """Writes the lit-sphere figure; returns the mean |file - interpolant| / mean (None without
    a grid). The grid (spectral, like the session) is compared with spectral files only."""
    if m.rgb:
        grid = None
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    bands = band_indices(m)
    inside, ti, pi, to, po = sphere_directions(size, [-0.5, 0.6, 0.62])
    img_file = render(inside, m.brdf(ti, pi, to, po)[:, bands], ti)
    panels = [("from the .bsdf (our reader)", img_file)]
    if grid:
        phi = np.degrees(np.abs(np.angle(np.exp(1j * (po - pi)))))
        g = grid_brdf(grid, np.degrees(ti), np.degrees(to), phi, bands)
        panels.append(("from the interpolant (grid export)", render(inside, g, ti)))
    peak = max(np.percentile(p[1], 99.5) for p in panels)
    fig, axs = plt.subplots(1, len(panels), figsize=(4 * len(panels) + 1, 4.3))
    for ax, (title, img) in zip(np.atleast_1d(axs), panels):
        ax.imshow(tonemap(img, peak))
        ax.set_title(title, fontsize=10)
        ax.axis("off")
    fig.suptitle("Lit sphere, " + ("linear sRGB" if m.rgb else "channels 610/550/465 nm") +
                 ", same exposure")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    if grid:
        return np.abs(panels[0][1] - panels[1][1])[inside].mean() / panels[1][1][inside].mean()
    return None


def plot_slices(m, path):
    """Writes the luminance / one-wavelength table figure."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    bands = band_indices(m)
    lum = m.fields["luminance"][0]
    vals = m.fields["rgb" if m.rgb else "spectra"][0][:, bands[1]]
    picks = np.linspace(0, lum.shape[0] - 1, 4).astype(int)
    fig, axs = plt.subplots(2, 4, figsize=(12, 6.4))
    for j, k in enumerate(picks):
        t = np.degrees(m.fields["theta_i"][k])
        axs[0, j].imshow(lum[k], origin="lower", extent=[0, 1, 0, 1])
        axs[0, j].set_title(f"luminance, θi = {t:.0f}°", fontsize=9)
        axs[1, j].imshow(vals[k], origin="lower", extent=[0, 1, 0, 1])
        label = "G" if m.rgb else f"{m.channels[bands[1]]:.0f} nm"
        axs[1, j].set_title(f"stored value {label}, θi = {t:.0f}°", fontsize=9)
    for ax in axs.flat:
        ax.set_xlabel("warped u (θm)", fontsize=8)
        ax.set_ylabel("warped v (φm)", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("file")
    ap.add_argument("--grid", help="a `brdf-export grid --nodes` .npy of the same session")
    ap.add_argument("--out", default=".")
    a = ap.parse_args(argv)
    m = Material(a.file)
    slices = os.path.join(a.out, "rgl_slices.png")
    sphere = os.path.join(a.out, "rgl_sphere.png")
    plot_slices(m, slices)
    diff = plot_sphere(m, sphere, a.grid)
    print(f"wrote {slices}\nwrote {sphere}")
    if diff is not None:
        print(f"sphere: mean |file - interpolant| / mean = {100 * diff:.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
