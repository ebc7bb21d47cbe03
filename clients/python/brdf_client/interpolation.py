"""Interpolation answers with their provenance, as NumPy (InterpolationResult, InterpolationBatch).

brdfd builds a spectrum at an unmeasured direction by blending measured readings: the paper's
octant method and Delaunay blend the 4 readings of an enclosing tetrahedron with barycentric
weights, nearest takes one. Each answer names those readings (vertices: reading id, position,
weight), so a figure can draw the tetrahedron and the spectra that went into the blend.
"""

import dataclasses
from typing import Any, Iterable, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import names
from ._stubs import brdf_pb2
from .readings import grid_wavelengths

ISO_AXES = ("theta_i", "theta_o", "phi")
FOUR_AXES = ("theta_i", "phi_i", "theta_o", "phi_o")


@dataclasses.dataclass
class Vertex:
    """One reading blended into an answer.

    reading_id: the reading (a mirrored or reciprocal copy keeps the id of the reading it copies).
    coords:     where it sits, degrees, in the query's axis order ((θi, θo, φ) for isotropic).
    weight:     its barycentric weight (the weights of an OK answer sum to 1).
    """

    reading_id: int
    coords: np.ndarray
    weight: float


@dataclasses.dataclass
class InterpolationUncertainty:
    """The standard uncertainties (k = 1) of an interpolated spectrum, per band, in its
    quantity's unit (brdf.v1.InterpolationUncertainty; docs/uncertainty.md, "Interpolated
    values"). Multiply by k (2: about 95 %) for an expanded uncertainty.

    measurement:   (m,) from the blended readings' budgets, shared terms (white standard, the
                   same reference, dark, instrument) correlated; empty when not estimated (a
                   quantity other than the BRDF).
    shared:        (m,) the part of `measurement` more readings would not reduce; empty in a
                   batch's answers unless asked (interpolate_batch(uncertainty_shared=True)).
    interpolation: (m,) the interpolant's own error, estimated from the vertices' spread; empty
                   when not estimated (nearest).
    combined:      (m,) sqrt(measurement² + interpolation²) of what was estimated. A batch's
                   answers do not carry it (brdf.proto): it is computed here from the two parts
                   as the daemon computes Interpolate's (in double from the float parts, rounded
                   to float32), so both give the same values.
    not_estimated: what is left out, each "what: why" (never silently zero).

    The daemon sends the parts as float32 (two significant digits mean something); they are
    float64 arrays here.
    """

    measurement: np.ndarray
    shared: np.ndarray
    interpolation: np.ndarray
    combined: np.ndarray
    not_estimated: List[str]

    @classmethod
    def from_proto(cls, u: Any, bands: int) -> "InterpolationUncertainty":
        """Converts a brdf.v1.InterpolationUncertainty of an answer of `bands` bands (its
        combined computed from the parts when the answer leaves it out)."""
        measurement = np.array(u.measurement, dtype=float)
        interpolation = np.array(u.interpolation, dtype=float)
        combined = (np.array(u.combined, dtype=float) if len(u.combined) > 0
                    else quadrature_sum(measurement, interpolation, bands))
        return cls(measurement=measurement, shared=np.array(u.shared, dtype=float),
                   interpolation=interpolation, combined=combined,
                   not_estimated=list(u.not_estimated))


def quadrature_sum(measurement: np.ndarray, interpolation: np.ndarray, bands: int) -> np.ndarray:
    """sqrt(measurement² + interpolation²) over `bands` bands, a part not estimated (empty)
    counting 0, in float64 and rounded to float32: brdf.proto's InterpolationUncertainty.combined,
    the same bits as the daemon's."""
    m = measurement if len(measurement) == bands else np.zeros(bands)
    i = interpolation if len(interpolation) == bands else np.zeros(bands)
    return np.sqrt(m * m + i * i).astype(np.float32).astype(float)


@dataclasses.dataclass
class InterpolationResult:
    """The answer for one direction.

    Attributes:
      query:       the direction asked for, degrees, in the order of `axes`.
      axes:        ("theta_i", "theta_o", "phi") or ("theta_i", "phi_i", "theta_o", "phi_o").
      status:      "ok", or why there is no spectrum: "empty_octant", "no_enclosing_simplex",
                   "outside_hull".
      method:      the method used: "octant", "delaunay" or "nearest".
      quantity:    "brdf" (sr⁻¹), "reflectance" (ratio) or "radiance" (W·m⁻²·sr⁻¹·nm⁻¹).
      wavelengths: (m,) nm.
      spectrum:    (m,) in the quantity's unit; empty unless ok.
      vertices:    the blended readings (octant and Delaunay: 4 for isotropic; nearest: 1).
      detail:      the daemon's note (which octant was empty, which tetrahedron enclosed).
      uncertainty: the spectrum's InterpolationUncertainty when asked for (uncertainty=True)
                   and ok; else None (not asked, which is not an uncertainty of zero).
    """

    query: np.ndarray
    axes: Tuple[str, ...]
    status: str
    method: str
    quantity: str
    wavelengths: np.ndarray
    spectrum: np.ndarray
    vertices: List[Vertex]
    detail: str
    uncertainty: Optional[InterpolationUncertainty] = None

    @property
    def ok(self) -> bool:
        """True when a spectrum was built."""
        return self.status == "ok"

    @property
    def unit(self) -> str:
        """The unit of `spectrum`, for labels ("sr⁻¹" for a BRDF)."""
        return names.QUANTITY_UNITS.get(self.quantity, "")

    @property
    def vertex_ids(self) -> np.ndarray:
        """(k,) reading ids of the vertices."""
        return np.array([v.reading_id for v in self.vertices], dtype=np.int64)

    @property
    def vertex_coords(self) -> np.ndarray:
        """(k, d) positions of the vertices, degrees, in the order of `axes`."""
        if not self.vertices:
            return np.zeros((0, len(self.axes)))
        return np.array([v.coords for v in self.vertices], dtype=float)

    @property
    def weights(self) -> np.ndarray:
        """(k,) barycentric weights of the vertices."""
        return np.array([v.weight for v in self.vertices], dtype=float)

    def at(self, wavelength_nm: float) -> float:
        """The spectrum at `wavelength_nm` (linear between bands; NaN when not ok)."""
        if not self.ok:
            return float("nan")
        lo, hi = self.wavelengths[0], self.wavelengths[-1]
        if not lo <= wavelength_nm <= hi:
            raise ValueError(f"{wavelength_nm} nm is outside the spectrum's {lo:g}–{hi:g} nm")
        return float(np.interp(wavelength_nm, self.wavelengths, self.spectrum))

    def to_dataset(self) -> Any:
        """This answer as an xarray Dataset: the spectrum over wavelength, the vertices' reading
        ids, weights and coordinates over vertex, status (interp_datasets.result_dataset)."""
        from .interp_datasets import result_dataset  # pylint: disable=import-outside-toplevel
        return result_dataset(self)

    @classmethod
    def from_proto(cls, result: Any) -> "InterpolationResult":
        """Converts a brdf.v1.InterpolationResult."""
        which = result.query.WhichOneof("direction")
        axes: Tuple[str, ...]
        query: Tuple[float, ...]
        if which == "four":
            d = result.query.four
            query, axes = (d.theta_i, d.phi_i, d.theta_o, d.phi_o), FOUR_AXES
        else:
            d = result.query.iso
            query, axes = (d.theta_i, d.theta_o, d.phi), ISO_AXES
        return cls(
            query=np.array(query, dtype=float), axes=axes,
            status=names.status_name(result.status), method=names.method_name(result.method),
            quantity=names.quantity_name(result.quantity),
            wavelengths=grid_wavelengths(result.grid),
            spectrum=np.array(result.spectrum, dtype=float),
            vertices=[Vertex(v.reading_id, np.array(v.coords, dtype=float), v.weight)
                      for v in result.vertices],
            detail=result.detail,
            uncertainty=(InterpolationUncertainty.from_proto(result.uncertainty,
                                                             len(result.spectrum))
                         if result.HasField("uncertainty") else None))


class InterpolationBatch:
    """The answers for many directions, in the order asked.

    Attributes:
      results:     list of InterpolationResult.
      wavelengths: (m,) nm (of the first OK answer; empty when none is OK).
      spectra:     (N, m), NaN rows where no spectrum could be built.
      ok:          (N,) bool.
      statuses:    (N,) str.
      u_measurement, u_interpolation, u_combined: (N, m) standard uncertainties (k = 1) of the
                   spectra when the batch asked for them (uncertainty=True); NaN where an answer
                   has none (not OK, not asked, or that part not estimated: see
                   results[i].uncertainty.not_estimated).
    """

    def __init__(self, results: Iterable[InterpolationResult]) -> None:
        self.results = list(results)
        good = [r for r in self.results if r.ok]
        self.wavelengths = good[0].wavelengths if good else np.zeros(0)
        m = len(self.wavelengths)
        self.spectra = np.full((len(self.results), m), np.nan)
        for i, r in enumerate(self.results):
            if r.ok and len(r.spectrum) == m:
                self.spectra[i] = r.spectrum
        self.u_measurement = self._uncertainty_rows("measurement", m)
        self.u_interpolation = self._uncertainty_rows("interpolation", m)
        self.u_combined = self._uncertainty_rows("combined", m)
        self.ok = np.array([r.ok for r in self.results], dtype=bool)
        self.statuses = np.array([r.status for r in self.results], dtype=object)

    def _uncertainty_rows(self, part: str, m: int) -> np.ndarray:
        rows = np.full((len(self.results), m), np.nan)
        for i, r in enumerate(self.results):
            values = getattr(r.uncertainty, part) if r.uncertainty is not None else ()
            if r.ok and len(values) == m:
                rows[i] = values
        return rows

    def __len__(self) -> int:
        return len(self.results)

    def __iter__(self) -> Iterator[InterpolationResult]:
        return iter(self.results)

    def __getitem__(self, i: int) -> InterpolationResult:
        return self.results[i]

    def to_dataset(self) -> Any:
        """The answers as an xarray Dataset over (direction, wavelength, vertex, axis): values,
        status, detail, the directions' angles, the vertices (interp_datasets.batch_dataset)."""
        from .interp_datasets import batch_dataset  # pylint: disable=import-outside-toplevel
        return batch_dataset(self)

    def at(self, wavelength_nm: float) -> np.ndarray:
        """(N,) the spectra at `wavelength_nm` (NaN where not OK)."""
        if len(self.wavelengths) == 0:
            return np.full(len(self.results), np.nan)
        return np.array([np.interp(wavelength_nm, self.wavelengths, s) if np.isfinite(s).all()
                         else np.nan for s in self.spectra])


def direction_query(direction: Sequence[float]) -> Any:
    """A brdf.v1.DirectionQuery from (θi, θo, φ) or (θi, φi, θo, φo), degrees."""
    d = [float(x) for x in direction]
    if len(d) == 3:
        return brdf_pb2.DirectionQuery(
            iso=brdf_pb2.IsoDirection(theta_i=d[0], theta_o=d[1], phi=d[2]))
    if len(d) == 4:
        return brdf_pb2.DirectionQuery(
            four=brdf_pb2.Directions(theta_i=d[0], phi_i=d[1], theta_o=d[2], phi_o=d[3]))
    raise ValueError(f"a direction is (θi, θo, φ) or (θi, φi, θo, φo) in degrees, "
                     f"not {len(d)} numbers")


def interpolation_options(axis_scale: Optional[Sequence[float]] = None,
                          mirror_phi: bool = False, reciprocity: bool = False,
                          coordinates: Union[str, int, None] = None,
                          trend: Union[str, int, None] = None) -> Any:
    """A brdf.v1.InterpolationOptions, or None when every option is at its default.

    coordinates: "incidence" (θi, θo, φ), "half_difference" (or "half-diff": Rusinkiewicz's
    half/difference angles, isotropic sessions only) or None (the daemon's default, incidence).
    trend: "none" (blend the readings' spectra), "bivariate" (blend their residuals from a
    smooth f(θh, θd) fitted to all of them and add it back; isotropic sessions only) or None
    (none). An unknown name raises ValueError."""
    coordinates = names.to_enum(coordinates, names.COORDINATES, "coordinates")
    trend = names.to_enum(trend, names.TRENDS, "trend")
    if not axis_scale and not mirror_phi and not reciprocity and not coordinates and not trend:
        return None
    return brdf_pb2.InterpolationOptions(axis_scale=list(axis_scale or []),
                                         mirror_phi=mirror_phi, reciprocity=reciprocity,
                                         coordinates=coordinates, trend=trend)
