"""What a session's sample looks like (Interpolation.RenderAppearance; docs/appearance.md): its
colour at the CIE 45°:0° geometry and a sphere lit by a distant light, in sRGB under CIE D65 and
illuminant A, computed by the daemon from the session's BRDF."""

from dataclasses import dataclass
from typing import Any, Dict, List, Sequence, Tuple, Union

import numpy as np

from ._stubs import brdf_pb2

ILLUMINANTS = {"D65": brdf_pb2.ILLUMINANT_D65, "A": brdf_pb2.ILLUMINANT_A}


@dataclass
class AppearanceImage:
    """The sample under one illuminant.

    name: "D65" or "A". xyz: CIE XYZ (Y = 1 for the perfect white), xy: chromaticity,
    linear_srgb: unclipped linear sRGB, hex: "#rrggbb" (8-bit sRGB). sphere: (n, n, 4) uint8
    RGBA, row 0 at the top, alpha 0 outside the disc; a white Lambertian lit head-on is Y = 1.
    counts: lit pixels by where their BRDF came from ("interpolated", "fallback", "model",
    "empty"), plus "disc" and "unlit". peak_y: the largest pixel Y (> 1: the highlight clips)."""
    name: str
    xyz: Tuple[float, float, float]
    xy: Tuple[float, float]
    linear_srgb: Tuple[float, float, float]
    hex: str
    sphere: np.ndarray
    counts: Dict[str, int]
    peak_y: float

    @classmethod
    def from_proto(cls, m: Any) -> "AppearanceImage":
        """From a brdf.v1.AppearanceImage."""
        c = m.colour
        n = m.sphere_size
        sphere = np.frombuffer(m.sphere_rgba, dtype=np.uint8).reshape(n, n, 4).copy()
        return cls(name=m.name, xyz=(c.x_tristimulus, c.y_tristimulus, c.z_tristimulus),
                   xy=(c.x, c.y), linear_srgb=(c.linear_r, c.linear_g, c.linear_b),
                   hex=c.srgb_hex, sphere=sphere,
                   counts={"disc": m.disc_pixels, "unlit": m.unlit_pixels,
                           "interpolated": m.interpolated_pixels,
                           "fallback": m.fallback_pixels, "model": m.model_pixels,
                           "empty": m.empty_pixels},
                   peak_y=m.peak_y)


@dataclass
class Appearance:
    """images: one AppearanceImage per illuminant, in the order asked (also by name through
    appearance["D65"]); wavelengths, reflectance: the reflectance factor π·f_r at 45°:0°;
    detail: readings left out, or what the fill chain could not do."""
    images: List[AppearanceImage]
    wavelengths: np.ndarray
    reflectance: np.ndarray
    detail: str

    def __getitem__(self, name: str) -> AppearanceImage:
        for image in self.images:
            if image.name == name:
                return image
        raise KeyError(f"no image under {name!r}; have {[i.name for i in self.images]}")

    @classmethod
    def from_proto(cls, m: Any) -> "Appearance":
        """From a brdf.v1.AppearanceResponse."""
        g = m.grid
        count = len(m.reflectance)
        return cls(images=[AppearanceImage.from_proto(i) for i in m.images],
                   wavelengths=g.start_nm + g.step_nm * np.arange(count),
                   reflectance=np.asarray(m.reflectance, dtype=float), detail=m.detail)


def illuminant_enums(illuminants: Union[str, Sequence[str], None]) -> List[int]:
    """["D65", "A"] (or one name, or None for the daemon's default: both) as the API's enums;
    an unknown name raises ValueError."""
    if illuminants is None:
        return []
    if isinstance(illuminants, str):
        illuminants = [illuminants]
    out = []
    for name in illuminants:
        if name not in ILLUMINANTS:
            raise ValueError(f"illuminant {name!r}: use one of {sorted(ILLUMINANTS)}")
        out.append(ILLUMINANTS[name])
    return out
