"""The API's enums in short lower-case words, both ways.

Calls accept a method, quantity, state or reading kind either as the enum value of the stubs
(brdf_pb2.INTERPOLATION_METHOD_DELAUNAY) or as its short name ("delaunay"); results report the
short names, which read well in prints and plot labels.
"""

from typing import Any, Mapping

from ._stubs import brdf_pb2, plan_pb2

METHODS = {
    "octant": brdf_pb2.INTERPOLATION_METHOD_OCTANT,
    "delaunay": brdf_pb2.INTERPOLATION_METHOD_DELAUNAY,
    "nearest": brdf_pb2.INTERPOLATION_METHOD_NEAREST,
}
# Where a method measures distances and blends (InterpolationOptions.coordinates). "half-diff",
# the command lines' spelling of "half_difference", arrives here as "half_diff" (to_enum).
COORDINATES = {
    "incidence": brdf_pb2.INTERPOLATION_COORDINATES_INCIDENCE,
    "half_difference": brdf_pb2.INTERPOLATION_COORDINATES_HALF_DIFFERENCE,
    "half_diff": brdf_pb2.INTERPOLATION_COORDINATES_HALF_DIFFERENCE,
}
# What a method blends (InterpolationOptions.trend).
TRENDS = {
    "none": brdf_pb2.INTERPOLATION_TREND_NONE,
    "bivariate": brdf_pb2.INTERPOLATION_TREND_BIVARIATE,
}
QUANTITIES = {
    "radiance": brdf_pb2.QUANTITY_RADIANCE,
    "reflectance": brdf_pb2.QUANTITY_REFLECTANCE,
    "brdf": brdf_pb2.QUANTITY_BRDF,
}
STATES = {
    "queued": brdf_pb2.SESSION_STATE_QUEUED,
    "running": brdf_pb2.SESSION_STATE_RUNNING,
    "pausing": brdf_pb2.SESSION_STATE_PAUSING,
    "paused": brdf_pb2.SESSION_STATE_PAUSED,
    "awaiting_operator": brdf_pb2.SESSION_STATE_AWAITING_OPERATOR,
    "completed": brdf_pb2.SESSION_STATE_COMPLETED,
    "aborted": brdf_pb2.SESSION_STATE_ABORTED,
    "failed": brdf_pb2.SESSION_STATE_FAILED,
}
TERMINAL_STATES = frozenset(
    (brdf_pb2.SESSION_STATE_COMPLETED, brdf_pb2.SESSION_STATE_ABORTED, brdf_pb2.SESSION_STATE_FAILED))
READING_KINDS = {
    "sample": brdf_pb2.READING_KIND_SAMPLE,
    "reference": brdf_pb2.READING_KIND_REFERENCE,
    "dark": brdf_pb2.READING_KIND_DARK,
}

# The unit of each quantity, for labels.
QUANTITY_UNITS = {"radiance": "W·m⁻²·sr⁻¹·nm⁻¹", "reflectance": "ratio", "brdf": "sr⁻¹"}


def _short(enum_name: str, prefix: str) -> str:
    return enum_name[len(prefix):].lower() if enum_name.startswith(prefix) else enum_name.lower()


def to_enum(value: Any, table: Mapping[str, int], what: str) -> int:
    """`value` (a short name or an enum number) as the enum number of `table`.

    None gives 0 (UNSPECIFIED: the daemon's default). A name not in `table` raises ValueError
    listing the accepted ones.
    """
    if value is None:
        return 0
    if isinstance(value, str):
        key = value.strip().lower().replace("-", "_")
        if key not in table:
            raise ValueError(f"unknown {what} {value!r}; use one of {', '.join(table)}")
        return table[key]
    return int(value)


def method_name(value: int) -> str:
    """brdf_pb2 InterpolationMethod number → "octant", "delaunay", "nearest" (or "unspecified")."""
    return _short(brdf_pb2.InterpolationMethod.Name(value), "INTERPOLATION_METHOD_")


def quantity_name(value: int) -> str:
    """Quantity number → "radiance", "reflectance", "brdf"."""
    return _short(brdf_pb2.Quantity.Name(value), "QUANTITY_")


def status_name(value: int) -> str:
    """InterpolationStatus number → "ok", "empty_octant", "no_enclosing_simplex", "outside_hull"."""
    return _short(brdf_pb2.InterpolationStatus.Name(value), "INTERPOLATION_STATUS_")


def state_name(value: int) -> str:
    """SessionState number → "queued", "running", ..., "completed"."""
    return _short(brdf_pb2.SessionState.Name(value), "SESSION_STATE_")


def reading_kind_name(value: int) -> str:
    """ReadingKind number → "sample", "reference", "dark"."""
    return _short(brdf_pb2.ReadingKind.Name(value), "READING_KIND_")


def prompt_kind_name(value: int) -> str:
    """PromptKind number → "mount_white", "relocate_detector", ..."""
    return _short(plan_pb2.PromptKind.Name(value), "PROMPT_KIND_")


def step_kind_name(value: int) -> str:
    """StepKind number → "move", "prompt", "reference", "dark", "sample"."""
    return _short(plan_pb2.StepKind.Name(value), "STEP_KIND_")
