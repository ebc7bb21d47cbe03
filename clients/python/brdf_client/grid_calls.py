"""Grids as Datasets from a live daemon: exported (Data.Export, BrdfClient.grid) or computed from
interpolations (Interpolation.InterpolateBatch, BrdfClient.interpolate_grid). BrdfClient's
methods document the arguments; this module does the work.
"""

import os
import tempfile
from typing import TYPE_CHECKING, Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from . import names
from .angles import incidence_from_half_diff
from .grid_datasets import cell_provenance, grid_dataset
from .interp_datasets import computed_grid_dataset
from .netcdf import write_netcdf

if TYPE_CHECKING:  # pragma: no cover
    from .client import BrdfClient

Steps = Union[float, Sequence[float]]
# Directions this far above 90° still count as on the horizon (rounding in the conversions).
HORIZON_SLACK_DEG = 1e-9


def grid_steps(step: Steps) -> Tuple[float, float, float]:
    """(θi, θo, φ) steps from one step for all three axes or three of them."""
    if isinstance(step, (int, float)):
        return float(step), float(step), float(step)
    values = tuple(float(s) for s in step)
    if len(values) != 3:
        raise ValueError(f"give one grid step or three (θi, θo, φ), not {len(values)}")
    return values[0], values[1], values[2]


def export_grid(client: "BrdfClient", session_id: str, step: Steps, *, method: Any,
                fill: str, provenance: bool, path: Optional[str], netcdf: Optional[str],
                progress: Optional[bool], **options: Any) -> Any:
    """BrdfClient.grid: the grid export as a Dataset, with per-cell provenance from up to two
    companion exports (fill "none" by the method and by Delaunay) when `provenance`."""
    ti, to, p = grid_steps(step)
    method_name = names.method_name(names.to_enum(method, names.METHODS, "method") or
                                    names.METHODS["octant"])
    common = dict(options, step_theta_i=ti, step_theta_o=to, step_phi=p)
    with tempfile.TemporaryDirectory(prefix="brdf_grid_") as tmp:
        target = os.fspath(path) if path else os.path.join(tmp, "grid.npy")
        if os.path.isdir(target):
            raise ValueError(f"{target} is a folder; give the .npy file to keep the grid in")
        main = client.export(session_id, "grid_npy", target, method=method_name, fill=fill,
                             sidecar=bool(path), progress=progress, **common)
        values = np.load(target)
        description = main.description or {}
        policy = str((description.get("fill") or {}).get("policy", fill))
        chosen = fallback = None
        if provenance and policy == "chain":
            companions = [method_name] + ([] if method_name == "delaunay" else ["delaunay"])
            arrays = []
            for name in companions:
                companion = os.path.join(tmp, f"{name}-fill-none.npy")
                client.export(session_id, "grid_npy", companion, method=name, fill="none",
                              progress=progress, **common)
                arrays.append(np.load(companion))
            chosen, fallback = arrays[0], (arrays[1] if len(arrays) > 1 else None)
        cells = cell_provenance(values, policy, chosen, fallback)
        ds = grid_dataset(values, description, cells,
                          source=target if path else "Data.Export")
    if netcdf:
        write_netcdf(ds, netcdf)
    return ds


def _mesh(axes: Dict[str, Any]) -> Tuple[np.ndarray, ...]:
    return tuple(np.meshgrid(*(np.asarray(v, float) for v in axes.values()), indexing="ij"))


def _check_range(name: str, values: np.ndarray, top: float) -> None:
    if values.size == 0:
        raise ValueError(f"{name}: give at least one angle")
    if np.any(~np.isfinite(values)) or values.min() < 0 or values.max() > top:
        raise ValueError(f"{name} must lie in [0°, {top:g}°]; got {values.min():g}° to "
                         f"{values.max():g}°")


def grid_directions(theta_i: Any = None, theta_o: Any = None, phi: Any = None,
                    theta_h: Any = None, theta_d: Any = None,
                    phi_d: Any = None) -> Tuple[Dict[str, np.ndarray], Tuple[np.ndarray, ...]]:
    """The axes asked for (incidence or half/difference, all three of one kind) and the
    (θi, θo, φ) of every cell."""
    incidence = {"theta_i": theta_i, "theta_o": theta_o, "phi": phi}
    half = {"theta_h": theta_h, "theta_d": theta_d, "phi_d": phi_d}
    given_i = [k for k, v in incidence.items() if v is not None]
    given_h = [k for k, v in half.items() if v is not None]
    if (len(given_i), len(given_h)) == (3, 0):
        axes = {k: np.atleast_1d(np.asarray(v, float)) for k, v in incidence.items()}
        for k, top in (("theta_i", 90.0), ("theta_o", 90.0), ("phi", 180.0)):
            _check_range(k, axes[k], top)
        return axes, _mesh(axes)
    if (len(given_i), len(given_h)) == (0, 3):
        axes = {k: np.atleast_1d(np.asarray(v, float)) for k, v in half.items()}
        for k, top in (("theta_h", 90.0), ("theta_d", 90.0), ("phi_d", 360.0)):
            _check_range(k, axes[k], top)
        return axes, incidence_from_half_diff(*_mesh(axes))
    raise ValueError("give the grid's axes as theta_i, theta_o and phi, or as theta_h, theta_d "
                     f"and phi_d (degrees); got {', '.join(given_i + given_h) or 'none'}")


def interpolate_grid(client: "BrdfClient", session_id: str, *, axes: Dict[str, Any],
                     method: Any, quantity: Any, progress: Optional[bool],
                     netcdf: Optional[str], timeout: Optional[float], chunk_size: int,
                     **options: Any) -> Any:
    """BrdfClient.interpolate_grid: one InterpolateBatch over the grid's cells above the
    horizon, as a Dataset (computed_grid_dataset)."""
    axis_values, (ti, to, p) = grid_directions(**axes)
    below = (ti > 90.0 + HORIZON_SLACK_DEG) | (to > 90.0 + HORIZON_SLACK_DEG)
    directions = np.stack([np.minimum(ti[~below], 90.0), np.minimum(to[~below], 90.0),
                           p[~below]], axis=-1)
    batch = client.interpolate_batch(session_id, directions, method=method, quantity=quantity,
                                     chunk_size=chunk_size, timeout=timeout, progress=progress,
                                     **options)
    described = {
        "method": names.method_name(names.to_enum(method, names.METHODS, "method")),
        "quantity": names.quantity_name(names.to_enum(quantity, names.QUANTITIES, "quantity")),
        "coordinates": options.get("coordinates") or "incidence",
        "trend": options.get("trend") or "none",
        "mirror_phi": bool(options.get("mirror_phi")),
        "reciprocity": bool(options.get("reciprocity")),
    }
    ds = computed_grid_dataset(batch, axis_values, below, (ti, to, p), described)
    if netcdf:
        write_netcdf(ds, netcdf)
    return ds
