"""Interpolation answers as xarray Datasets: one answer, a batch, and a grid computed from a batch.

    r = brdf.interpolate(sid, 35, 40, 40).to_dataset()
    r.brdf.plot(); r.vertex_weight                      # spectrum (wavelength); weights (vertex)
    b = brdf.interpolate_batch(sid, dirs).to_dataset()   # brdf (direction, wavelength), status, ...
    g = brdf.interpolate_grid(sid, theta_i=[20, 40], theta_o=range(0, 80, 5), phi=[0, 90, 180])

Layout (labels.py: names and units). A batch: the quantity's values (direction, wavelength), NaN
rows where no spectrum; status and detail (direction); the direction's angles as coordinates along
direction (theta_i, theta_o, phi, or theta_i, phi_i, theta_o, phi_o); vertex_reading_id
(direction, vertex; 0 where an answer has fewer vertices), vertex_weight and vertex_coords
(direction, vertex, axis; NaN there). Answers asked with uncertainty=True add the standard
uncertainties (k = 1) as {quantity}_uncertainty (combined), {quantity}_uncertainty_measurement and
{quantity}_uncertainty_interpolation (direction, wavelength; NaN where not estimated).
One answer: the same without the direction dimension.
A computed grid: the values (axis1, axis2, axis3, wavelength) and status / provenance per cell.
"""

from typing import TYPE_CHECKING, Any, Dict, Sequence, Tuple

import numpy as np

from . import labels

if TYPE_CHECKING:  # pragma: no cover
    from .interpolation import InterpolationBatch, InterpolationResult


def _attrs(method: str, quantity: str) -> Dict[str, Any]:
    return {"method": method, "quantity": quantity,
            "unit": labels.quantity_attrs(quantity)["units"],
            "uncertainty": labels.UNCERTAINTY_NOTE.format(
                name=labels.uncertainty_name(quantity), quantity=quantity)}


def _vertices(results: Sequence["InterpolationResult"], axes: Tuple[str, ...]) -> Dict[str, Any]:
    """vertex_reading_id, vertex_weight, vertex_coords padded to the most vertices of any answer."""
    k = max((len(r.vertices) for r in results), default=0)
    ids = np.zeros((len(results), k), dtype=np.int64)
    weights = np.full((len(results), k), np.nan)
    coords = np.full((len(results), k, len(axes)), np.nan)
    for i, r in enumerate(results):
        n = len(r.vertices)
        if n:
            ids[i, :n], weights[i, :n] = r.vertex_ids, r.weights
            coords[i, :n, :] = r.vertex_coords[:, :len(axes)]
    return {
        "vertex_reading_id": (("direction", "vertex"), ids,
                              {"long_name": "the reading blended (0: none)"}),
        "vertex_weight": (("direction", "vertex"), weights,
                          {"long_name": "barycentric weight (the weights of an ok answer sum "
                                        "to 1)"}),
        "vertex_coords": (("direction", "vertex", "axis"), coords,
                          {"long_name": "where the reading sits", "units": labels.ANGLE_UNITS}),
    }


def _uncertainties(results: Sequence["InterpolationResult"], quantity: str,
                   m: int) -> Dict[str, Any]:
    """The answers' uncertainty variables, or none when no answer carries one."""
    if not any(r.uncertainty is not None for r in results):
        return {}
    out: Dict[str, Any] = {}
    name = labels.uncertainty_name(quantity)
    units = labels.quantity_attrs(quantity).get("units", "")
    for part, suffix, what in (("combined", "", "combined"),
                               ("measurement", "_measurement", "from the readings' budgets"),
                               ("interpolation", "_interpolation", "the interpolant's own")):
        rows = np.full((len(results), m), np.nan)
        for i, r in enumerate(results):
            values = getattr(r.uncertainty, part) if r.uncertainty is not None else ()
            if r.ok and len(values) == m:
                rows[i] = values
        out[name + suffix] = (("direction", "wavelength"), rows,
                              {"long_name": f"standard uncertainty (k = 1), {what}",
                               "units": units})
    return out


def _answers(results: Sequence["InterpolationResult"], wavelengths: np.ndarray,
             spectra: np.ndarray) -> Any:
    """The Dataset of answers over (direction, wavelength, vertex, axis)."""
    xr = labels.xarray()
    axes: Tuple[str, ...] = results[0].axes if results else ("theta_i", "theta_o", "phi")
    quantity = results[0].quantity if results else "brdf"
    method = results[0].method if results else ""
    queries = (np.array([r.query for r in results], dtype=float) if results
               else np.zeros((0, len(axes))))
    coords: Dict[str, Any] = {
        "direction": ("direction", np.arange(len(results))),
        "wavelength": ("wavelength", np.asarray(wavelengths, float),
                       labels.COORD_ATTRS["wavelength"]),
        "axis": ("axis", list(axes)),
    }
    for k, name in enumerate(axes):
        coords[name] = ("direction", queries[:, k], labels.COORD_ATTRS[name])
    data_vars: Dict[str, Any] = {
        quantity: (("direction", "wavelength"), np.asarray(spectra, float),
                   labels.quantity_attrs(quantity)),
        "status": ("direction", np.array([r.status for r in results], dtype=object),
                   {"long_name": "ok, or why the method could not fill the direction"}),
        "detail": ("direction", np.array([r.detail for r in results], dtype=object)),
        **_vertices(results, axes),
    }
    uncertainties = _uncertainties(results, quantity, len(wavelengths))
    data_vars.update(uncertainties)
    attrs = _attrs(method, quantity)
    if uncertainties:
        attrs["uncertainty"] = (f"{labels.uncertainty_name(quantity)}: standard uncertainty "
                                "(k = 1); docs/uncertainty.md, 'Interpolated values'")
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def batch_dataset(batch: "InterpolationBatch") -> Any:
    """An InterpolationBatch as a Dataset over (direction, wavelength, vertex, axis)."""
    return _answers(list(batch.results), batch.wavelengths, batch.spectra)


def result_dataset(result: "InterpolationResult") -> Any:
    """One InterpolationResult as a Dataset: the spectrum (wavelength; NaN when not ok), its
    vertices (vertex), status and detail; the direction's angles as scalar coordinates."""
    m = len(result.wavelengths)
    spectrum = (np.asarray(result.spectrum, float) if result.ok and len(result.spectrum) == m
                else np.full(m, np.nan))
    ds = _answers([result], result.wavelengths, spectrum[None, :])
    return ds.isel(direction=0).drop_vars("direction")


def computed_grid_dataset(batch: "InterpolationBatch", axes: Dict[str, np.ndarray],
                          below_horizon: np.ndarray, incidence: Tuple[np.ndarray, ...],
                          options: Dict[str, Any]) -> Any:
    """A grid whose cells are the answers of `batch` in C order over the axes' cells above the
    horizon (`below_horizon` False). axes: three names → values (θi θo φ, or θh θd φd);
    incidence: (θi, θo, φ) of every cell, kept as coordinates when the axes are half/difference;
    options: the method and options asked (0-d variables)."""
    xr = labels.xarray()
    names = list(axes)
    shape = tuple(len(v) for v in axes.values())
    quantity = batch.results[0].quantity if len(batch) else str(options.get("quantity", "brdf"))
    m = len(batch.wavelengths)
    values = np.full(shape + (m,), np.nan)
    status = np.full(shape, "below_horizon", dtype=object)
    above = ~below_horizon
    values[above] = batch.spectra
    status[above] = batch.statuses
    code = labels.PROVENANCE_CODE
    provenance = np.where(status == "ok", code["interpolated"], code["empty"]).astype(np.int8)
    coords: Dict[str, Any] = {n: (n, np.asarray(v, float), labels.COORD_ATTRS[n])
                              for n, v in axes.items()}
    coords["wavelength"] = ("wavelength", np.asarray(batch.wavelengths, float),
                            labels.COORD_ATTRS["wavelength"])
    if names[0] != "theta_i":
        for n, v in zip(("theta_i", "theta_o", "phi"), incidence):
            coords[n] = (tuple(names), v, labels.COORD_ATTRS[n])
    data_vars: Dict[str, Any] = {
        quantity: (tuple(names) + ("wavelength",), values,
                   {**labels.quantity_attrs(quantity), "ancillary_variables": "provenance status"}),
        "status": (tuple(names), status,
                   {"long_name": "ok, or why the cell has no value (below_horizon: a direction "
                                 "under the surface, not asked)"}),
        "provenance": (tuple(names), provenance, labels.provenance_attrs()),
        "fill_policy": ((), "none"),
    }
    for key, value in options.items():
        if key != "quantity":
            data_vars[key] = ((), value)
    attrs = _attrs(str(options.get("method", "")), quantity)
    attrs["source"] = "Interpolation.InterpolateBatch"
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)
