"""Reflectance and BRDF of stored readings, recomputed from the raw spectra.

brdfd keeps readings raw; the quantities come from geometry.md ("Reflectance and BRDF"), the same
formulas the daemon applies (core/spectrum.h):

  R(λ) = (I(λ) − D(λ)) / (I0(λ) − D(λ))                    reflectance, a ratio
  f(λ) = R(λ) · ρw / π · cos θi,ref / cos θi               BRDF, sr⁻¹

I is the SAMPLE reading, I0 the REFERENCE reading it names (reference_ids), D the DARK reading
the sample names (dark_ids; none: 0), subtracted from both (a plan's dark is taken right after
its reference, so the sample's dark is the one that goes with that reference), θi the sample
reading's incidence angle, θi,ref the reference's, and ρw the white standard's reflectance. ρw is a daemon setting
([sample] white_reflectance, default 0.99, the paper's RS-3) that the API does not report, so it
is a parameter here.

Figure 8 uses this for the spectra of an interpolation's vertices.
"""

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from .interpolation import InterpolationResult
    from .readings import ReadingSet

QUANTITIES = ("radiance", "reflectance", "brdf")


def _dark(readings: "ReadingSet", dark_id: int) -> Any:
    if dark_id == 0:
        return 0.0
    return readings.spectra[readings.index_of(dark_id)]


def reading_spectrum(readings: "ReadingSet", reading_id: int, quantity: str = "brdf",
                     white_reflectance: float = 0.99) -> np.ndarray:
    """The spectrum of SAMPLE reading `reading_id` in `quantity`, from the raw readings.

    `readings` is a ReadingSet holding that reading, its reference and its dark (load the
    session with every kind). Raises KeyError when one of them is missing, ValueError when the
    reading is not a SAMPLE or the reference is not positive after the dark (it cannot be divided
    by), or for a grazing angle (cos θ = 0).
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"unknown quantity {quantity!r}; use one of {', '.join(QUANTITIES)}")
    i = readings.index_of(reading_id)
    if readings.kinds[i] != "sample":
        raise ValueError(f"reading {reading_id} is a {readings.kinds[i]} reading, not a sample")
    dark = _dark(readings, readings.dark_ids[i])
    sample = readings.spectra[i] - dark
    if quantity == "radiance":
        return sample
    ref_id = int(readings.reference_ids[i])
    if ref_id == 0:
        raise ValueError(f"sample reading {reading_id} names no reference reading")
    r = readings.index_of(ref_id)
    white = readings.spectra[r] - dark
    if np.any(white <= 0):
        band = int(np.flatnonzero(white <= 0)[0])
        raise ValueError(f"reference reading {ref_id} is not above its dark at "
                         f"{readings.wavelengths[band]:g} nm; it cannot be divided by")
    reflectance = sample / white
    if quantity == "reflectance":
        return reflectance
    cos_i = np.cos(np.radians(readings.directions[i, 0]))
    cos_ref = np.cos(np.radians(readings.directions[r, 0]))
    if cos_i <= 0 or cos_ref <= 0:
        raise ValueError(f"sample reading {reading_id} (θi {readings.directions[i, 0]:g}°) or its "
                         f"reference (θi,ref {readings.directions[r, 0]:g}°) is at grazing "
                         "incidence; the BRDF is undefined there")
    return reflectance * white_reflectance / np.pi * cos_ref / cos_i


def vertex_spectra(readings: "ReadingSet", result: "InterpolationResult",
                   white_reflectance: float = 0.99) -> np.ndarray:
    """(k, m) the spectra of an interpolation's vertices, in the result's quantity."""
    return np.array([reading_spectrum(readings, v.reading_id, result.quantity, white_reflectance)
                     for v in result.vertices])
