"""A session's readings as NumPy arrays (ReadingSet).

brdfd stores every reading raw (spectral radiance as the meter reported it, with its pose and
provenance); a ReadingSet holds n of them column-wise, so analysis code can slice by kind, pose
or direction without loops. Units: degrees for angles, nm for wavelengths, W·m⁻²·sr⁻¹·nm⁻¹ for
radiance (brdf.proto). Each sample reading may carry the uncertainty budget brdfd stored with it
(docs/uncertainty.md): the standard uncertainty of its BRDF per band and its components.
"""

import dataclasses
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import names

# brdf.v1.UncertaintySharing's short names, by enum number.
SHARINGS = {1: "independent", 2: "reference_reading", 3: "dark_reading", 4: "white_standard",
            5: "instrument"}


@dataclasses.dataclass
class UncertaintyComponent:
    """One named component of a reading's uncertainty (brdf.v1.UncertaintyComponent).

    sharing: "independent", "reference_reading", "dark_reading", "white_standard" or
    "instrument"; shared_id: the reference or dark reading it is shared through (0: the
    session's); contribution: (m,) signed cⱼ · u(xⱼ) per band, in the quantity's unit. Two readings
    sharing a component through the same (sharing, shared_id) covary by the product of their
    contributions; independent ones never covary."""

    sharing: str
    shared_id: int
    contribution: np.ndarray


@dataclasses.dataclass
class UncertaintyBudget:
    """A reading's uncertainty budget (brdf.v1.ReadingUncertainty), per band of its grid.

    quantity: "brdf" (sr⁻¹) or "reflectance"; value: the quantity the budget was evaluated at;
    combined: the standard uncertainty u_c (k = 1); independent: its part independent of every
    other reading; components: by name; not_estimated: "name: why" of the terms left out."""

    quantity: str
    value: np.ndarray
    combined: np.ndarray
    independent: np.ndarray
    components: Dict[str, UncertaintyComponent]
    not_estimated: List[str]

    @classmethod
    def from_proto(cls, u: Any) -> "UncertaintyBudget":
        """From a brdf.v1.ReadingUncertainty."""
        return cls(
            quantity=names.quantity_name(u.quantity),
            value=np.array(u.value, dtype=float), combined=np.array(u.combined, dtype=float),
            independent=np.array(u.independent, dtype=float),
            components={c.name: UncertaintyComponent(SHARINGS.get(c.sharing, "unspecified"),
                                                     int(c.shared_id),
                                                     np.array(c.contribution, dtype=float))
                        for c in u.components},
            not_estimated=list(u.not_estimated))


def _budgets(readings: Sequence[Any], m: int) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(budgets, u, u_independent): each reading's UncertaintyBudget or None, and the BRDF's
    standard uncertainties (n, m), NaN where not estimated (never 0)."""
    budgets = np.array([UncertaintyBudget.from_proto(r.uncertainty)
                        if r.HasField("uncertainty") else None for r in readings], dtype=object)
    u = np.full((len(readings), m), np.nan)
    u_ind = np.full((len(readings), m), np.nan)
    for i, b in enumerate(budgets):
        if b is not None and b.quantity == "brdf" and len(b.combined) == m:
            u[i], u_ind[i] = b.combined, b.independent
    return budgets, u, u_ind


def grid_wavelengths(grid: Any) -> np.ndarray:
    """The wavelengths (nm) of a brdf.v1.WavelengthGrid: start_nm + k · step_nm, k < count."""
    return grid.start_nm + grid.step_nm * np.arange(grid.count, dtype=float)


@dataclasses.dataclass
class ReadingSet:
    """n readings of one session, column-wise. Row i of every array is reading i.

    Attributes:
      ids:            (n,) int64 reading ids, increasing in the order they were taken.
      kinds:          (n,) str, "sample", "reference" or "dark".
      step_index:     (n,) int, the plan step that took each reading.
      poses:          (n, 4) holder and detector pose (α, β, γ, δ), degrees (stage readings).
      directions:     (n, 4) (θi, φi, θo, φo), degrees, in the sample's frame.
      iso:            (n, 3) (θi, θo, φ), degrees: the isotropic reduction (φ = 180 specular side).
      wavelengths:    (m,) nm, shared by every reading.
      spectra:        (n, m) spectral radiance, W·m⁻²·sr⁻¹·nm⁻¹, as measured (darks not subtracted).
      quality:        (n,) the meter's quality code (PR-650: 0 OK, 18 low light, ...).
      flagged:        (n,) bool, kept but suspect (see flag_reasons).
      flag_reasons:   (n,) str.
      reference_ids:  (n,) the REFERENCE reading a SAMPLE reading is divided by; 0 otherwise.
      dark_ids:       (n,) the DARK reading subtracted from a SAMPLE/REFERENCE reading; 0: none.
      integration_ms: (n,) integration time actually used, ms.
      integration_notes: (n,) str, how the meter's quality policy changed the integration time to
                      take it (e.g. halved after an overload); "" when it used the plan's.
      labels:         (n,) str, the plan step's label.
      brdf_uncertainty: (n, m) the standard uncertainty (k = 1) of each sample reading's BRDF,
                      sr⁻¹, from the budget brdfd stored with it; NaN where not estimated
                      (references, darks, readings from before budgets) — never 0.
      brdf_uncertainty_independent: (n, m) its part independent of every other reading; NaN
                      likewise. The rest of u² is shared (white standard, reference, …): see
                      budgets, and docs/uncertainty.md for combining readings.
      budgets:        (n,) object: each reading's UncertaintyBudget, or None (not estimated).
    """

    ids: np.ndarray
    kinds: np.ndarray
    step_index: np.ndarray
    poses: np.ndarray
    directions: np.ndarray
    iso: np.ndarray
    wavelengths: np.ndarray
    spectra: np.ndarray
    quality: np.ndarray
    flagged: np.ndarray
    flag_reasons: np.ndarray
    reference_ids: np.ndarray
    dark_ids: np.ndarray
    integration_ms: np.ndarray
    labels: np.ndarray
    integration_notes: Optional[np.ndarray] = None
    brdf_uncertainty: Optional[np.ndarray] = None
    brdf_uncertainty_independent: Optional[np.ndarray] = None
    budgets: Optional[np.ndarray] = None

    def __post_init__(self) -> None:
        # Sets built without budgets (older code, synthetic data): every reading not estimated.
        n, m = len(self.ids), len(self.wavelengths)
        if self.integration_notes is None:
            self.integration_notes = np.full(n, "", dtype=object)
        if self.brdf_uncertainty is None:
            self.brdf_uncertainty = np.full((n, m), np.nan)
        if self.brdf_uncertainty_independent is None:
            self.brdf_uncertainty_independent = np.full((n, m), np.nan)
        if self.budgets is None:
            self.budgets = np.full(n, None, dtype=object)

    def __len__(self) -> int:
        return len(self.ids)

    def to_dataframe(self) -> Any:
        """One row per reading as a pandas DataFrame, indexed by reading id: kind, pose,
        directions, quality, flags, ids (reading_tables.readings_dataframe)."""
        from .reading_tables import readings_dataframe  # pylint: disable=import-outside-toplevel
        return readings_dataframe(self)

    def to_dataarray(self, quantity: str = "radiance", white_reflectance: float = 0.99) -> Any:
        """The spectra as an xarray DataArray (reading × wavelength): "radiance" (every reading),
        or "reflectance" / "brdf" (the sample readings, recomputed as the daemon does;
        white_reflectance: ρw). See reading_tables.readings_dataarray."""
        from .reading_tables import readings_dataarray  # pylint: disable=import-outside-toplevel
        return readings_dataarray(self, quantity, white_reflectance)

    @classmethod
    def empty(cls, wavelengths: Optional[Sequence[float]] = None) -> "ReadingSet":
        """A set of no readings (on `wavelengths`, default none)."""
        m = 0 if wavelengths is None else len(wavelengths)
        return cls(
            ids=np.zeros(0, dtype=np.int64), kinds=np.zeros(0, dtype=object),
            step_index=np.zeros(0, dtype=int), poses=np.zeros((0, 4)), directions=np.zeros((0, 4)),
            iso=np.zeros((0, 3)),
            wavelengths=np.zeros(0) if wavelengths is None else np.asarray(wavelengths, float),
            spectra=np.zeros((0, m)), quality=np.zeros(0, dtype=int),
            flagged=np.zeros(0, dtype=bool), flag_reasons=np.zeros(0, dtype=object),
            reference_ids=np.zeros(0, dtype=np.int64), dark_ids=np.zeros(0, dtype=np.int64),
            integration_ms=np.zeros(0, dtype=int), labels=np.zeros(0, dtype=object))

    @classmethod
    def from_protos(cls, readings: Iterable[Any]) -> "ReadingSet":
        """Builds a set from brdf.v1.Reading messages (all on the same wavelength grid)."""
        readings = list(readings)
        if not readings:
            return cls.empty()
        grid = readings[0].grid
        for r in readings:
            if (r.grid.start_nm, r.grid.step_nm, r.grid.count) != (grid.start_nm, grid.step_nm,
                                                                    grid.count):
                raise ValueError(
                    f"reading {r.id} is on a different wavelength grid ({r.grid.start_nm} nm + "
                    f"{r.grid.step_nm} nm × {r.grid.count}) than reading {readings[0].id} "
                    f"({grid.start_nm} nm + {grid.step_nm} nm × {grid.count}); load them apart")
            if len(r.radiance) != grid.count:
                raise ValueError(f"reading {r.id} has {len(r.radiance)} radiance values for a "
                                 f"grid of {grid.count} bands")
        return cls(
            ids=np.array([r.id for r in readings], dtype=np.int64),
            kinds=np.array([names.reading_kind_name(r.kind) for r in readings], dtype=object),
            step_index=np.array([r.step_index for r in readings], dtype=int),
            poses=np.array([(r.pose.alpha, r.pose.beta, r.pose.gamma, r.pose.delta)
                            for r in readings], dtype=float),
            directions=np.array([(r.directions.theta_i, r.directions.phi_i, r.directions.theta_o,
                                  r.directions.phi_o) for r in readings], dtype=float),
            iso=np.array([(r.iso.theta_i, r.iso.theta_o, r.iso.phi) for r in readings],
                         dtype=float),
            wavelengths=grid_wavelengths(grid),
            spectra=np.array([list(r.radiance) for r in readings], dtype=float),
            quality=np.array([r.quality_code for r in readings], dtype=int),
            flagged=np.array([r.flagged for r in readings], dtype=bool),
            flag_reasons=np.array([r.flag_reason for r in readings], dtype=object),
            reference_ids=np.array([r.reference_id for r in readings], dtype=np.int64),
            dark_ids=np.array([r.dark_id for r in readings], dtype=np.int64),
            integration_ms=np.array([r.integration_ms for r in readings], dtype=int),
            integration_notes=np.array([r.integration_note for r in readings], dtype=object),
            labels=np.array([r.label for r in readings], dtype=object),
            **dict(zip(("budgets", "brdf_uncertainty", "brdf_uncertainty_independent"),
                       _budgets(readings, grid.count))))

    @classmethod
    def concat(cls, sets: Iterable["ReadingSet"]) -> "ReadingSet":
        """One set holding the readings of `sets`, in order."""
        sets = [s for s in sets if len(s)]
        if not sets:
            return cls.empty()
        for s in sets[1:]:
            if not np.array_equal(s.wavelengths, sets[0].wavelengths):
                raise ValueError("cannot join readings on different wavelength grids")
        fields = {}
        for f in dataclasses.fields(cls):
            if f.name == "wavelengths":
                fields[f.name] = sets[0].wavelengths
            else:
                fields[f.name] = np.concatenate([getattr(s, f.name) for s in sets])
        return cls(**fields)

    def select(self, mask: Any) -> "ReadingSet":
        """The readings where `mask` (a bool array or index array) holds."""
        fields = {f.name: (getattr(self, f.name) if f.name == "wavelengths" else
                           getattr(self, f.name)[mask]) for f in dataclasses.fields(self)}
        return ReadingSet(**fields)

    def of_kind(self, kind: str) -> "ReadingSet":
        """Only the readings of `kind` ("sample", "reference" or "dark")."""
        return self.select(self.kinds == kind)

    def index_of(self, reading_id: int) -> int:
        """Row of the reading with this id; KeyError when it is not in the set."""
        rows = np.flatnonzero(self.ids == reading_id)
        if rows.size == 0:
            raise KeyError(f"reading {reading_id} is not in this set of {len(self)} readings")
        return int(rows[0])


# Reading kinds accepted by BrdfClient.readings(kinds=...).
def kinds_to_enums(kinds: Union[str, int, Sequence[Union[str, int]], None]) -> list:
    """("sample", ...) or enum numbers → the ReadingKind numbers StreamReadings filters on."""
    if kinds is None:
        return []
    if isinstance(kinds, (str, int)):
        kinds = [kinds]
    return [names.to_enum(k, names.READING_KINDS, "reading kind") for k in kinds]

