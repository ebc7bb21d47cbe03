"""Incidence angles (θi, θo, φ) and Rusinkiewicz's half/difference angles (θh, θd, φd), both ways,
for isotropic samples (φh = 0), in degrees, on NumPy arrays of any shape.

Conventions (docs/geometry.md, docs/interpolation.md): φ = |φo − φi| folded into [0°, 180°], 180°
the specular side; h = (ωi + ωo)/|ωi + ωo|; the difference vector is ωi seen from a frame whose
pole is h. θd = 0 is retro-reflection (ωo = ωi), θh = 0 the mirror direction (φ = 180°).
"""

from typing import Tuple

import numpy as np

Array = np.ndarray


def _unit(theta: Array, phi: Array) -> Array:
    t, p = np.radians(theta), np.radians(phi)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def _fold_phi(phi: Array) -> Array:
    """Azimuth differences into [0°, 180°]."""
    p = np.mod(phi, 360.0)
    return np.where(p > 180.0, 360.0 - p, p)


def incidence_from_half_diff(theta_h: Array, theta_d: Array,
                             phi_d: Array) -> Tuple[Array, Array, Array]:
    """(θi, θo, φ) of the directions at (θh, θd, φd) with φh = 0. A θi or θo above 90° is below
    the surface: the caller decides what such a cell holds (grids: NaN, "below_horizon")."""
    th, td, pd = np.broadcast_arrays(*(np.asarray(a, float) for a in (theta_h, theta_d, phi_d)))
    d = _unit(td, pd)
    c, s = np.cos(np.radians(th)), np.sin(np.radians(th))
    # ωi = R_y(θh) d; h = (sin θh, 0, cos θh); ωo = 2 (ωi·h) h − ωi.
    wi = np.stack([d[..., 0] * c + d[..., 2] * s, d[..., 1], -d[..., 0] * s + d[..., 2] * c],
                  axis=-1)
    h = np.stack([s, np.zeros_like(s), c], axis=-1)
    wo = 2.0 * np.sum(wi * h, axis=-1, keepdims=True) * h - wi
    theta_i = np.degrees(np.arccos(np.clip(wi[..., 2], -1.0, 1.0)))
    theta_o = np.degrees(np.arccos(np.clip(wo[..., 2], -1.0, 1.0)))
    phi = _fold_phi(np.degrees(np.arctan2(wo[..., 1], wo[..., 0]) -
                               np.arctan2(wi[..., 1], wi[..., 0])))
    return theta_i, theta_o, phi


def half_diff_from_incidence(theta_i: Array, theta_o: Array,
                             phi: Array) -> Tuple[Array, Array, Array]:
    """(θh, θd, φd) of the directions (θi, φi = 0, θo, φo = φ); φd folded into [0°, 180°]
    (isotropic and reciprocal: φd and φd + 180° are the same pair of directions)."""
    ti, to, p = np.broadcast_arrays(*(np.asarray(a, float) for a in (theta_i, theta_o, phi)))
    wi = _unit(ti, np.zeros_like(ti))
    wo = _unit(to, p)
    h = wi + wo
    h /= np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    theta_h = np.arccos(np.clip(h[..., 2], -1.0, 1.0))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    # d = R_y(−θh) R_z(−φh) ωi
    cp, sp = np.cos(-phi_h), np.sin(-phi_h)
    x, y, z = wi[..., 0] * cp - wi[..., 1] * sp, wi[..., 0] * sp + wi[..., 1] * cp, wi[..., 2]
    ct, st = np.cos(-theta_h), np.sin(-theta_h)
    dx, dz = x * ct + z * st, -x * st + z * ct
    theta_d = np.degrees(np.arccos(np.clip(dz, -1.0, 1.0)))
    phi_d = _fold_phi(np.degrees(np.arctan2(y, dx)))
    return np.degrees(theta_h), theta_d, phi_d
