"""What the labelled structures share: dimension names, units, provenance codes, and the
reserved place of uncertainties.

The client hands back pandas DataFrames and xarray DataArrays / Datasets whose axes carry their
names and units, so that nothing has to be remembered next to an array:

  dimension / coordinate   meaning                                          unit
  reading                  a reading's id (brdfd's, increasing)             –
  wavelength               band centre λ                                    nm
  theta_i, theta_o         incidence and viewing zenith angles θi, θo       degree
  phi                      relative azimuth φ = |φo − φi|, 180° specular    degree
  phi_i, phi_o             azimuths in the sample's frame (anisotropic)     degree
  theta_h, theta_d, phi_d  Rusinkiewicz's half/difference angles            degree
  alpha, beta, gamma, delta  the rig's pose (holder α β γ, detector arm δ)   degree
  direction                the index of a direction asked for               –
  vertex                   the k-th reading blended into an answer          –

A quantity's values ("radiance", "reflectance", "brdf") carry attrs `quantity`, `units` (the
daemon's unit string, e.g. "sr⁻¹") and `long_name`. Every Dataset keeps room for the
uncertainties that a later API adds: `uncertainty_name("brdf")` == "brdf_uncertainty", a variable
of the same dimensions and unit as "brdf" once the daemon reports it; until then it is absent and
the Dataset's attr `uncertainty` says so.
"""

import importlib
from types import ModuleType
from typing import Dict

from . import names

ANGLE_UNITS = "degree"

COORD_ATTRS: Dict[str, Dict[str, str]] = {
    "theta_i": {"long_name": "incidence zenith angle θi", "units": ANGLE_UNITS},
    "theta_o": {"long_name": "viewing zenith angle θo", "units": ANGLE_UNITS},
    "phi": {"long_name": "relative azimuth φ = |φo − φi| (180° = specular side)",
            "units": ANGLE_UNITS},
    "phi_i": {"long_name": "incidence azimuth φi (sample frame)", "units": ANGLE_UNITS},
    "phi_o": {"long_name": "viewing azimuth φo (sample frame)", "units": ANGLE_UNITS},
    "theta_h": {"long_name": "half-vector zenith angle θh (Rusinkiewicz)", "units": ANGLE_UNITS},
    "theta_d": {"long_name": "difference zenith angle θd (Rusinkiewicz)", "units": ANGLE_UNITS},
    "phi_d": {"long_name": "difference azimuth φd (Rusinkiewicz)", "units": ANGLE_UNITS},
    "alpha": {"long_name": "holder rotation α", "units": ANGLE_UNITS},
    "beta": {"long_name": "holder tilt β", "units": ANGLE_UNITS},
    "gamma": {"long_name": "holder dial γ", "units": ANGLE_UNITS},
    "delta": {"long_name": "detector arm δ", "units": ANGLE_UNITS},
    "wavelength": {"long_name": "wavelength λ", "units": "nm"},
}

QUANTITY_LONG_NAMES = {
    "radiance": "spectral radiance I (as measured)",
    "reflectance": "reflectance factor R = (I − D) / (I0 − D)",
    "brdf": "spectral BRDF f = R · ρw / π · cos θi,ref / cos θi",
}

# Where a grid cell's value came from (grids: the variable "provenance", int8). The first four are
# the daemon's fill chain's words (ExportFillCounts); "unrecorded": filled by the chain, but the
# file does not say by which stage (a chain grid read from a file without its companions).
PROVENANCE = ("interpolated", "fallback", "model", "empty", "unrecorded")
PROVENANCE_CODE = {name: code for code, name in enumerate(PROVENANCE)}

UNCERTAINTY_NOTE = ("not reported yet: a later API adds it as the variable {name} (same "
                    "dimensions and unit as {quantity})")


def uncertainty_name(quantity: str) -> str:
    """The variable that will hold the standard uncertainty of `quantity` ("brdf_uncertainty")."""
    return f"{quantity}_uncertainty"


def quantity_attrs(quantity: str, unit: str = "") -> Dict[str, str]:
    """attrs of a quantity's values: quantity, units (the daemon's string), long_name."""
    return {"quantity": quantity, "units": unit or names.QUANTITY_UNITS.get(quantity, ""),
            "long_name": QUANTITY_LONG_NAMES.get(quantity, quantity)}


def provenance_attrs() -> Dict[str, object]:
    """CF-style attrs of the provenance codes (flag_values, flag_meanings)."""
    return {"long_name": "where the cell's value came from",
            "flag_values": list(range(len(PROVENANCE))), "flag_meanings": " ".join(PROVENANCE)}


def _require(module: str, debian: str) -> ModuleType:
    """`module` imported, or ImportError naming the Debian package that brings it."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(f"brdf_client's labelled data needs {module}: sudo apt-get install "
                          f"{debian} (or pip install {module})") from e


def xarray() -> ModuleType:
    """The xarray module, or ImportError saying how to get it (Debian's python3-xarray)."""
    return _require("xarray", "python3-xarray")


def pandas() -> ModuleType:
    """The pandas module, or ImportError saying how to get it (Debian's python3-pandas)."""
    return _require("pandas", "python3-pandas")
