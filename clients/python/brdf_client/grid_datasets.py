"""A grid export (the .npy array and its JSON description, the "sidecar") as an xarray Dataset.

The daemon's grid is a 4-D float64 array (θi, θo, φ, band) whose axes, units, method, options and
fill counts travel apart, in ExportResult.description (brdfctl writes it as GRID.npy.json). Here
they come together, cell for cell the same numbers:

    ds = brdf_client.open_grid("grid.npy")          # reads grid.npy and grid.npy.json
    ds.brdf.sel(theta_i=32.5, wavelength=552)        # a (θo, φ) slice, sr⁻¹
    ds.provenance                                    # per cell: interpolated, fallback, model, ...

Dataset layout (labels.py names the dimensions and units):
  <quantity>   (theta_i, theta_o, phi, wavelength): the values, attrs quantity, units, long_name,
               definition; NaN where nothing filled the cell.
  provenance   (theta_i, theta_o, phi) int8, flag_values / flag_meanings: labels.PROVENANCE.
  method, coordinates, trend, fill_policy: 0-d strings; mirror_phi, reciprocity: 0-d booleans;
  axis_scale   (scaled_axis): the method's axis weights (all 1 when the sidecar says null);
  fill_count   (fill_source): cells each stage of the fill chain filled, and those left empty;
  status_count (status): cells by the method's status (ok, or why not; the sidecar's by_status).
  attrs: session, session_name, quantity, unit, angles, samples, samples_left_out, cells,
  filled, nan_cells, model_fraction, sidecar (the description as JSON text), uncertainty.
"""

import json
import os
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple

import numpy as np

from . import labels

FILL_SOURCES = labels.PROVENANCE[:4]  # interpolated, fallback, model, empty


def axis_values(axis: Mapping[str, Any]) -> np.ndarray:
    """The values of a sidecar axis {"start", "step", "count"}: start + k · step (as brdfd)."""
    return float(axis["start"]) + float(axis["step"]) * np.arange(int(axis["count"]), dtype=float)


def filled_cells(values: np.ndarray) -> np.ndarray:
    """(…) bool: the cells of a (…, bands) array that hold a value (finite in every band)."""
    return np.isfinite(values).all(axis=-1)


def cell_provenance(values: np.ndarray, policy: str, chosen: Optional[np.ndarray] = None,
                    fallback: Optional[np.ndarray] = None) -> np.ndarray:
    """Per-cell provenance codes (labels.PROVENANCE_CODE) of a grid filled by `policy`.

    policy "none": interpolated where filled, empty elsewhere. policy "chain": the same grid
    exported with fill "none" by the chosen method (`chosen`) and by Delaunay (`fallback`; None
    when Delaunay is the chosen method) tell the stages apart: interpolated where `chosen` has a
    value, fallback where only `fallback` has one, model where neither does but the chain did;
    without `chosen` the filled cells are "unrecorded".
    """
    filled = filled_cells(values)
    code = labels.PROVENANCE_CODE
    out = np.where(filled, code["interpolated"], code["empty"]).astype(np.int8)
    if policy != "chain":
        return out
    if chosen is None:
        out[filled] = code["unrecorded"]
        return out
    by_method = filled_cells(chosen)
    by_fallback = filled_cells(fallback) if fallback is not None else np.zeros_like(by_method)
    out[filled & ~by_method] = code["model"]
    out[filled & ~by_method & by_fallback] = code["fallback"]
    return out


def _scalar_vars(description: Mapping[str, Any]) -> Dict[str, Any]:
    """The method and options as 0-d variables (and axis_scale along the scaled axes)."""
    coordinates = str(description.get("coordinates", "incidence"))
    scaled: Tuple[str, ...] = (("theta_h", "theta_d", "phi_d") if coordinates == "half_difference"
              else ("theta_i", "theta_o", "phi"))
    scale = description.get("axis_scale")
    scale_values = np.ones(len(scaled)) if scale is None else np.asarray(scale, float)
    if len(scale_values) != len(scaled):
        scaled = tuple(f"axis_{k}" for k in range(len(scale_values)))
    fill = description.get("fill") or {}
    return {
        "method": ((), str(description.get("method", "")), {"long_name": "interpolation method"}),
        "coordinates": ((), coordinates, {"long_name": "where the method measured and blended"}),
        "trend": ((), str(description.get("trend", "none")), {"long_name": "what was blended"}),
        "mirror_phi": ((), bool(description.get("mirror_phi", False)),
                       {"long_name": "readings mirrored at φ = 0° and 180°"}),
        "reciprocity": ((), bool(description.get("reciprocity", False)),
                        {"long_name": "θi↔θo swapped readings added"}),
        "axis_scale": (("scaled_axis",), scale_values,
                       {"long_name": "the method's axis weights",
                        "sidecar_value": "null (all 1)" if scale is None else "given"}),
        "fill_policy": ((), str(fill.get("policy", "none")),
                        {"long_name": "what filled the cells the method could not"}),
        "_scaled_axis": scaled,
    }


def _count_vars(description: Mapping[str, Any]) -> Dict[str, Any]:
    fill = description.get("fill") or {}
    by_status = description.get("by_status") or {}
    return {
        "fill_count": (("fill_source",), np.array([int(fill.get(s, 0)) for s in FILL_SOURCES],
                                                  dtype=np.int64),
                       {"long_name": "cells per fill stage (the sidecar's fill)"}),
        "status_count": (("status",), np.array([int(n) for n in by_status.values()],
                                               dtype=np.int64),
                         {"long_name": "cells by the method's status (ok, or why it could not "
                                       "fill them; the sidecar's by_status)"}),
        "_statuses": list(by_status.keys()),
    }


def _attrs(description: Mapping[str, Any], source: str) -> Dict[str, Any]:
    quantity = str(description.get("quantity", ""))
    fill = description.get("fill") or {}
    attrs: Dict[str, Any] = {
        "title": f"brdfd grid of session {description.get('session', '')}: {quantity}",
        "source": source, "format": str(description.get("format", "")),
        "session": int(description.get("session", 0)),
        "session_name": str(description.get("session_name", "")),
        "quantity": quantity, "unit": str(description.get("unit", "")),
        "definition": str(description.get("definition", "")),
        "angles": str(description.get("angles", "")),
        "model_fraction": float(fill.get("model_fraction", 0.0)),
        "uncertainty": labels.UNCERTAINTY_NOTE.format(name=labels.uncertainty_name(quantity),
                                                      quantity=quantity),
        "sidecar": json.dumps(description, ensure_ascii=False),
    }
    for key in ("samples", "samples_left_out", "cells", "filled", "nan_cells"):
        attrs[key] = int(description.get(key, 0))
    return attrs


def grid_dataset(values: np.ndarray, description: Mapping[str, Any],
                 provenance: Optional[np.ndarray] = None, source: str = "") -> Any:
    """The Dataset of a grid export: `values` (nθi, nθo, nφ, bands) as the daemon wrote them and
    `description` (ExportResult.description, or the .npy.json sidecar). `provenance`: per-cell
    codes (cell_provenance); None: from the fill policy alone (fill "chain": "unrecorded")."""
    xr = labels.xarray()
    values = np.asarray(values)
    shape = tuple(int(n) for n in description.get("shape", ()))
    if values.shape != shape:
        raise ValueError(f"the grid holds {values.shape} values but its description says "
                         f"{shape}; give the description of this very export")
    quantity = str(description.get("quantity", "brdf"))
    coords: Dict[str, Any] = {}
    for dim, key in (("theta_i", "theta_i_deg"), ("theta_o", "theta_o_deg"), ("phi", "phi_deg"),
                     ("wavelength", "wavelength_nm")):
        coords[dim] = (dim, axis_values(description[key]), labels.COORD_ATTRS[dim])
    if provenance is None:
        policy = str((description.get("fill") or {}).get("policy", "none"))
        provenance = cell_provenance(values, policy)
    scalars, counts = _scalar_vars(description), _count_vars(description)
    coords["scaled_axis"] = ("scaled_axis", list(scalars.pop("_scaled_axis")))
    coords["fill_source"] = ("fill_source", list(FILL_SOURCES))
    coords["status"] = ("status", counts.pop("_statuses"))
    value_attrs = {**labels.quantity_attrs(quantity, str(description.get("unit", ""))),
                   "definition": str(description.get("definition", "")),
                   "ancillary_variables": "provenance"}
    data_vars: Dict[str, Any] = {
        quantity: (("theta_i", "theta_o", "phi", "wavelength"), values, value_attrs),
        "provenance": (("theta_i", "theta_o", "phi"), np.asarray(provenance, np.int8),
                       labels.provenance_attrs()),
        **scalars, **counts,
    }
    return xr.Dataset(data_vars, coords=coords, attrs=_attrs(description, source))


def read_sidecar(path: str) -> Dict[str, Any]:
    """The JSON description of a grid file (GRID.npy.json, as brdfctl writes it)."""
    try:
        with open(path, encoding="utf-8") as f:
            description: Dict[str, Any] = json.load(f)
    except OSError as e:
        raise OSError(f"cannot read the grid's description {path}: {e.strerror}; brdfctl export "
                      "writes it next to the .npy (GRID.npy.json)") from e
    return description


def open_grid(path: "str | os.PathLike[str]", sidecar: Optional[str] = None,
              companions: Sequence[Optional[str]] = ()) -> Any:
    """A grid export read from files as a Dataset (grid_dataset's layout).

    path: the .npy (brdfctl export ID grid -o F.npy, BrdfClient.export or BrdfClient.grid with
    path=). sidecar: its description (default: path + ".json"). companions: for a "chain" grid,
    the same grid exported with fill "none" by the chosen method and by Delaunay (omit the
    second when Delaunay is the method), which give each cell's provenance; without them the
    chain's cells are "unrecorded" (fill_count still says how many each stage filled).
    """
    path = os.fspath(path)
    description = read_sidecar(sidecar or path + ".json")
    values = np.load(path)
    provenance = None
    if companions:
        policy = str((description.get("fill") or {}).get("policy", "none"))
        arrays = [np.load(p) if p else None for p in companions] + [None]
        provenance = cell_provenance(values, policy, arrays[0], arrays[1])
    return grid_dataset(values, description, provenance, source=path)
