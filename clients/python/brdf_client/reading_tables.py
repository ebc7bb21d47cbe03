"""A ReadingSet as a pandas DataFrame (one row per reading) and its spectra as an xarray
DataArray (reading × wavelength). ReadingSet.to_dataframe / to_dataarray call these.

    df = data.to_dataframe()                   # index reading_id; kind, pose, directions, ...
    df[df.kind == "sample"].plot.scatter("theta_o", "phi")
    rad = data.to_dataarray()                  # radiance, W·m⁻²·sr⁻¹·nm⁻¹, every reading
    f = data.to_dataarray("brdf")              # sr⁻¹, the sample readings (ρw: white_reflectance)
    f.sel(wavelength=550, method="nearest").plot.line(x="reading")
    u = f.brdf_uncertainty                     # its standard uncertainty (k = 1), NaN: not estimated
"""

from typing import TYPE_CHECKING, Any, Dict

import numpy as np

from . import labels
from .spectra import QUANTITIES, reading_spectrum

if TYPE_CHECKING:  # pragma: no cover
    from .readings import ReadingSet

# The DataFrame's columns in order, with the unit of those that have one.
POSE = ("alpha", "beta", "gamma", "delta")
DIRECTIONS = ("theta_i", "phi_i", "theta_o", "phi_o")
COLUMN_UNITS = {**{c: labels.ANGLE_UNITS for c in POSE + DIRECTIONS + ("phi",)},
                "integration_ms": "ms"}


def _estimated(readings: "ReadingSet") -> np.ndarray:
    """Per reading: True when it carries an uncertainty budget."""
    budgets = readings.budgets if readings.budgets is not None else np.full(len(readings), None)
    return np.array([b is not None for b in budgets], dtype=np.bool_)


def _columns(readings: "ReadingSet") -> Dict[str, Any]:
    """Per-reading values by column name (everything but the spectra)."""
    cols: Dict[str, Any] = {"kind": readings.kinds, "step_index": readings.step_index,
                            "label": readings.labels}
    for k, name in enumerate(POSE):
        cols[name] = readings.poses[:, k]
    for k, name in enumerate(DIRECTIONS):
        cols[name] = readings.directions[:, k]
    cols["phi"] = readings.iso[:, 2]
    cols.update(quality=readings.quality, flagged=readings.flagged,
                flag_reason=readings.flag_reasons, reference_id=readings.reference_ids,
                dark_id=readings.dark_ids, integration_ms=readings.integration_ms,
                integration_note=readings.integration_notes,
                uncertainty_estimated=_estimated(readings))
    return cols


def readings_dataframe(readings: "ReadingSet") -> Any:
    """One row per reading, indexed by reading id ("reading_id").

    Columns: kind ("sample", "reference", "dark"), step_index, label; the pose alpha, beta,
    gamma, delta and the directions theta_i, phi_i, theta_o, phi_o, phi (φ = |φo − φi|, 180°
    specular), degrees; quality (the meter's code), flagged, flag_reason; reference_id, dark_id
    (the readings a sample is divided by / a dark subtracted from it; 0: none); integration_ms,
    integration_note (how the meter changed the integration time; "" when it did not);
    uncertainty_estimated (the reading has an uncertainty budget: ReadingSet.budgets).
    `df.attrs["units"]` gives each column's unit, `df.attrs["wavelength_nm"]` the spectra's bands
    (the spectra themselves: to_dataarray).
    """
    pd = labels.pandas()
    df = pd.DataFrame(_columns(readings), index=pd.Index(readings.ids, name="reading_id"))
    df.attrs["units"] = dict(COLUMN_UNITS)
    df.attrs["wavelength_nm"] = np.asarray(readings.wavelengths, float).tolist()
    return df


def _derived_spectra(readings: "ReadingSet", quantity: str, white_reflectance: float) -> Any:
    """(ids, values): the sample readings' spectra in `quantity`, NaN where one cannot be had
    (no reference, a reference not above its dark, grazing incidence)."""
    rows = np.flatnonzero(readings.kinds == "sample")
    values = np.full((len(rows), len(readings.wavelengths)), np.nan)
    for out, row in enumerate(rows):
        try:
            values[out] = reading_spectrum(readings, int(readings.ids[row]), quantity,
                                           white_reflectance)
        except (KeyError, ValueError):
            pass
    return rows, values


def _uncertainty_coords(readings: "ReadingSet", rows: Any) -> Dict[str, Any]:
    """The BRDF's standard uncertainties as (reading, wavelength) coordinates."""
    name = labels.uncertainty_name("brdf")
    u_attrs = {"long_name": "standard uncertainty (k = 1) of the BRDF", "units": "sr⁻¹",
               "note": "NaN: not estimated; docs/uncertainty.md"}
    ind_attrs = dict(u_attrs, long_name="its part independent of every other reading")
    return {name: (("reading", "wavelength"), np.asarray(readings.brdf_uncertainty)[rows], u_attrs),
            name + "_independent": (("reading", "wavelength"),
                                    np.asarray(readings.brdf_uncertainty_independent)[rows],
                                    ind_attrs)}


def readings_dataarray(readings: "ReadingSet", quantity: str = "radiance",
                       white_reflectance: float = 0.99) -> Any:
    """The readings' spectra as an xarray DataArray (reading × wavelength).

    quantity: "radiance" (every reading as the meter gave it, W·m⁻²·sr⁻¹·nm⁻¹, darks not
    subtracted), "reflectance" or "brdf" (the SAMPLE readings, recomputed as the daemon does,
    brdf_client.spectra; NaN rows where a reading cannot be converted). white_reflectance: ρw,
    the daemon's [sample] white_reflectance, for "brdf".
    Coordinates: reading (ids), wavelength (nm), and along reading: kind, alpha … delta,
    theta_i, phi_i, theta_o, phi_o, phi, flagged. For "brdf" also brdf_uncertainty and
    brdf_uncertainty_independent (reading × wavelength): the standard uncertainty (k = 1) brdfd
    stored with each reading and its part independent of the others, sr⁻¹; NaN where not
    estimated. (The budget is of the BRDF; radiance and reflectance carry none.)
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"unknown quantity {quantity!r}; use one of {', '.join(QUANTITIES)}")
    xr = labels.xarray()
    if quantity == "radiance":
        rows, values = np.arange(len(readings)), np.asarray(readings.spectra, float)
    else:
        rows, values = _derived_spectra(readings, quantity, white_reflectance)
    cols = _columns(readings)
    coords: Dict[str, Any] = {
        "reading": ("reading", readings.ids[rows], {"long_name": "reading id"}),
        "wavelength": ("wavelength", np.asarray(readings.wavelengths, float),
                       labels.COORD_ATTRS["wavelength"]),
    }
    for name in ("kind",) + POSE + DIRECTIONS + ("phi", "flagged"):
        coords[name] = ("reading", np.asarray(cols[name])[rows],
                        labels.COORD_ATTRS.get(name, {}))
    attrs: Dict[str, Any] = labels.quantity_attrs(quantity)
    if quantity == "brdf":
        attrs["white_reflectance"] = white_reflectance
        coords.update(_uncertainty_coords(readings, rows))
    return xr.DataArray(values, dims=("reading", "wavelength"), coords=coords, name=quantity,
                        attrs=attrs)
