"""Session exports (Data.Export): the request from Python arguments, and what an export produced.

brdfd writes a session as a file — the readings as CSV, the session's interpolator on a regular
(θi, θo, φ) grid as a NumPy .npy or CSV, a MERL .binary, an RGL material .bsdf (spectral or
RGB; brdf_client.rgl reads it), or a BiRD universal BRDF JSON file (the sample readings with
their uncertainties and the session's provenance; docs/bird-format.md) — and streams it back: progress
messages, the file's bytes in order, then a report. BrdfClient.export saves the bytes; this module
builds the ExportRequest the way `brdfctl export` does (same words, same defaults) and turns the
report into an ExportResult. The formats are described in tools/brdf-export/README.md.
"""

import dataclasses
import json
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import names
from ._stubs import brdf_pb2

# What to export, in brdfctl's words ("grid" picks npy or CSV from the file name) and the
# proto's (ExportFormat without its prefix).
FORMATS = {
    "csv": brdf_pb2.EXPORT_FORMAT_READINGS_CSV,
    "readings_csv": brdf_pb2.EXPORT_FORMAT_READINGS_CSV,
    "grid_npy": brdf_pb2.EXPORT_FORMAT_GRID_NPY,
    "npy": brdf_pb2.EXPORT_FORMAT_GRID_NPY,
    "grid_csv": brdf_pb2.EXPORT_FORMAT_GRID_CSV,
    "merl": brdf_pb2.EXPORT_FORMAT_MERL_BINARY,
    "merl_binary": brdf_pb2.EXPORT_FORMAT_MERL_BINARY,
    "rgl": brdf_pb2.EXPORT_FORMAT_RGL_BSDF,
    "rgl_bsdf": brdf_pb2.EXPORT_FORMAT_RGL_BSDF,
    "bird": brdf_pb2.EXPORT_FORMAT_BIRD_JSON,
    "bird_json": brdf_pb2.EXPORT_FORMAT_BIRD_JSON,
}
# Formats whose cells the fill policy covers, and the policies by name.
FILLED_FORMATS = frozenset((brdf_pb2.EXPORT_FORMAT_GRID_NPY, brdf_pb2.EXPORT_FORMAT_GRID_CSV,
                            brdf_pb2.EXPORT_FORMAT_MERL_BINARY, brdf_pb2.EXPORT_FORMAT_RGL_BSDF))
FILLS = {"chain": brdf_pb2.EXPORT_FILL_CHAIN, "none": brdf_pb2.EXPORT_FILL_NONE}
GRID_FORMATS = frozenset((brdf_pb2.EXPORT_FORMAT_GRID_NPY, brdf_pb2.EXPORT_FORMAT_GRID_CSV))
# Formats that carry their cells' uncertainty on request (include_uncertainty).
UNCERTAIN_FORMATS = frozenset((brdf_pb2.EXPORT_FORMAT_GRID_NPY, brdf_pb2.EXPORT_FORMAT_MERL_BINARY,
                               brdf_pb2.EXPORT_FORMAT_RGL_BSDF))


def part_path(path: str, name: str, daemon_file_name: str) -> str:
    """Where companion part `name` of an export saved at `path` goes: path's stem, ".name", and
    the extension of the daemon's name for the part ("x.npy", "u", "….u.npy" → "x.u.npy";
    "x.binary", "uncertainty", "….uncertainty.json" → "x.uncertainty.json"), as brdfctl."""
    stem, _ = os.path.splitext(path)
    _, ext = os.path.splitext(daemon_file_name)
    return f"{stem}.{name}{ext}"


def format_name(value: int) -> str:
    """ExportFormat number → "readings_csv", "grid_npy", "grid_csv", "merl_binary", "rgl_bsdf",
    "bird_json"."""
    name = brdf_pb2.ExportFormat.Name(value)
    return name[len("EXPORT_FORMAT_"):].lower()


def export_format(fmt: Union[str, int], path: "str | os.PathLike[str]" = "") -> int:
    """`fmt` as an ExportFormat number.

    fmt: "csv" (the readings), "grid" (the regular grid: CSV when `path` ends in ".csv", else
    .npy), "merl", "rgl", "bird" (BiRD universal BRDF JSON); or the proto's names "readings_csv",
    "grid_npy", "grid_csv", "merl_binary", "rgl_bsdf", "bird_json";
    or an ExportFormat number. Anything else raises ValueError listing the accepted words.
    """
    if isinstance(fmt, str) and fmt.strip().lower() == "grid":
        is_csv = os.fspath(path).lower().endswith(".csv")
        return brdf_pb2.EXPORT_FORMAT_GRID_CSV if is_csv else brdf_pb2.EXPORT_FORMAT_GRID_NPY
    if isinstance(fmt, str):
        key = fmt.strip().lower().replace("-", "_")
        if key not in FORMATS:
            raise ValueError(f"unknown export format {fmt!r}; use csv, grid, merl, rgl, bird (or "
                             "readings_csv, grid_npy, grid_csv, merl_binary, rgl_bsdf, "
                             "bird_json)")
        return FORMATS[key]
    value = int(fmt)
    if value not in brdf_pb2.ExportFormat.values() or value == 0:
        raise ValueError(f"unknown export format {fmt!r}; use csv, grid, merl, rgl or bird")
    return value


def export_request(session_id: str, fmt: Union[str, int], path: str = "", *,
                   quantity: Union[str, int, None] = None, method: Union[str, int] = "octant",
                   axis_scale: Optional[Sequence[float]] = None, mirror_phi: bool = False,
                   reciprocity: Optional[bool] = None, step_theta_i: float = 0.0,
                   step_theta_o: float = 0.0, step_phi: float = 0.0, grid_nodes: bool = False,
                   exclude_flagged: bool = False, chunk_bytes: int = 0, fill: str = "chain",
                   rgb: bool = False, rgl_theta_i_count: int = 0, rgl_resolution: int = 0,
                   coordinates: Union[str, int, None] = None,
                   trend: Union[str, int, None] = None, float32: bool = False,
                   uncertainty: bool = False) -> Any:
    """The ExportRequest for BrdfClient.export's arguments (which document them).

    As brdfctl: reciprocity None means on for MERL and RGL (a cell stands for a pair of
    directions and its swap alike) and off for the others. Grid steps on a non-grid export, RGL
    options on another and a fill other than "chain" on the readings CSV raise ValueError rather
    than being silently ignored; the daemon checks the rest (INVALID_ARGUMENT).
    """
    value = export_format(fmt, path)
    rgl = value == brdf_pb2.EXPORT_FORMAT_RGL_BSDF
    if not rgl and (rgb or rgl_theta_i_count or rgl_resolution):
        raise ValueError(f"rgb, rgl_theta_i_count and rgl_resolution are for RGL exports, not "
                         f"{format_name(value)}")
    if float32 and value != brdf_pb2.EXPORT_FORMAT_GRID_NPY:
        raise ValueError(f"float32 is for grids as .npy, not {format_name(value)}")
    if uncertainty and value not in UNCERTAIN_FORMATS:
        raise ValueError(f"uncertainty is for grids as .npy, MERL and RGL, not "
                         f"{format_name(value)} (the readings CSV has u_<λ> columns and BiRD "
                         "uBRDF always)")
    fill_key = str(fill).strip().lower()
    if fill_key not in FILLS:
        raise ValueError(f"unknown fill {fill!r}; use chain or none")
    if value not in FILLED_FORMATS and fill_key != "chain":
        raise ValueError(f"fill is for grid, MERL and RGL exports, not {format_name(value)}")
    steps = (step_theta_i, step_theta_o, step_phi)
    if value not in GRID_FORMATS and (any(steps) or grid_nodes):
        raise ValueError(f"grid steps and grid_nodes are for grid exports, not "
                         f"{format_name(value)}")
    if reciprocity is None:
        reciprocity = value == brdf_pb2.EXPORT_FORMAT_MERL_BINARY or rgl
    coordinates = names.to_enum(coordinates, names.COORDINATES, "coordinates")
    if value not in FILLED_FORMATS and coordinates not in (
            0, brdf_pb2.INTERPOLATION_COORDINATES_INCIDENCE):
        raise ValueError(f"coordinates are for grid, MERL and RGL exports, not "
                         f"{format_name(value)}")
    trend = names.to_enum(trend, names.TRENDS, "trend")
    if value not in FILLED_FORMATS and trend not in (0, brdf_pb2.INTERPOLATION_TREND_NONE):
        raise ValueError(f"trend is for grid, MERL and RGL exports, not {format_name(value)}")
    options = brdf_pb2.InterpolationOptions(axis_scale=list(axis_scale or ()),
                                            mirror_phi=mirror_phi, reciprocity=reciprocity,
                                            coordinates=coordinates, trend=trend)
    return brdf_pb2.ExportRequest(
        session_id=str(session_id), format=value,
        quantity=names.to_enum(quantity, names.QUANTITIES, "quantity"),
        method=names.to_enum(method, names.METHODS, "method"), options=options,
        step_theta_i=step_theta_i, step_theta_o=step_theta_o, step_phi=step_phi,
        grid_nodes=grid_nodes, exclude_flagged=exclude_flagged, chunk_bytes=chunk_bytes,
        fill=FILLS[fill_key] if value in FILLED_FORMATS else 0, rgb=rgb,
        rgl_theta_i_count=rgl_theta_i_count, rgl_resolution=rgl_resolution, float32=float32,
        include_uncertainty=uncertainty)


@dataclasses.dataclass
class ExportResult:
    """What an export produced (the daemon's ExportReport, and where the file went).

    Attributes:
      path:        the file written (the `path` given, or the daemon's file name in that folder).
      format:      "readings_csv", "grid_npy", "grid_csv", "merl_binary", "rgl_bsdf" or
                   "bird_json".
      file_name:   the daemon's name for the file, e.g. "session-3-grid-brdf.npy".
      bytes:       size of the file (checked against the bytes received).
      summary:     one line, e.g. "16200 cells: 15012 ok, 1188 NaN (1100 empty_octant, …)".
      rows:        readings CSV: rows written (readings; for reflectance and BRDF the sample
                   readings that could be converted); BiRD JSON: points written (readings ×
                   bands).
      cells, filled_cells, unfilled_cells: grids, MERL and RGL: cells in the file, with a value,
                   without one (NaN in a grid; −1 in a MERL file, below-horizon cells excluded;
                   RGL: the nodes of all θi slices).
      unfilled_by_status: {"empty_octant": n, ...}: unfilled cells by why.
      below_horizon_cells, clamped_cells: MERL, RGL: cells below the surface (−1; RGL 0);
                   filled cells with a negative linear-sRGB component set to 0.
      skipped_readings, first_skip_reason: sample readings left out, and why the first one was.
      shape:       grid .npy: (nθi, nθo, nφ, bands); else ().
      description: grid .npy: the axes, wavelengths, quantity, unit, method, options (mirror_phi,
                   reciprocity, coordinates, axis_scale), fill and counts (the
                   report's description_json, parsed); else None.
      warnings:    things to know, e.g. several dial positions γ folded together, or (BiRD)
                   uBRDF left out because a reading has no uncertainty budget.
      fill:        grids, MERL, RGL: where the cells' values came from, {"policy": "chain" or
                   "none", "interpolated": n, "fallback": n, "model": n, "empty": n,
                   "model_fraction": x}; None for the readings CSV.
      parts:       with uncertainty=True: {part name: path} of the files saved beside `path`
                   ("u", "u_measurement", "u_interpolation" for a grid; "uncertainty" for MERL
                   and RGL); the description's "uncertainty" names the same files.
    """

    path: str
    format: str
    file_name: str
    bytes: int
    summary: str
    rows: int = 0
    cells: int = 0
    filled_cells: int = 0
    unfilled_cells: int = 0
    unfilled_by_status: Dict[str, int] = dataclasses.field(default_factory=dict)
    below_horizon_cells: int = 0
    clamped_cells: int = 0
    skipped_readings: int = 0
    first_skip_reason: str = ""
    shape: Tuple[int, ...] = ()
    description: Optional[Dict[str, Any]] = None
    warnings: List[str] = dataclasses.field(default_factory=list)
    fill: Optional[Dict[str, Any]] = None
    parts: Dict[str, str] = dataclasses.field(default_factory=dict)

    def write_sidecar(self) -> str:
        """Writes `description` as JSON next to the file (`path`.json, as brdfctl does);
        returns that path. ValueError for an export without a description (not a .npy grid)."""
        if self.description is None:
            raise ValueError(f"{self.path} ({self.format}) has no description to write; only "
                             ".npy grids have one")
        sidecar = self.path + ".json"
        with open(sidecar, "w", encoding="utf-8") as f:
            json.dump(self.description, f, indent=2, ensure_ascii=False)
            f.write("\n")
        return sidecar

    def to_dataset(self, provenance: Any = None) -> Any:
        """A .npy grid export as an xarray Dataset (grid_datasets.grid_dataset), read from
        `path` with `description`; ValueError for another format."""
        if self.description is None:
            raise ValueError(f"{self.path} ({self.format}) is not a .npy grid")
        from .grid_datasets import grid_dataset  # pylint: disable=import-outside-toplevel
        return grid_dataset(np.load(self.path), self.description, provenance, source=self.path)

    @classmethod
    def from_report(cls, report: Any, path: str, fmt: int,
                    parts: Optional[Dict[str, str]] = None) -> "ExportResult":
        """From a brdf_pb2.ExportReport, the saved file's path and the ExportFormat number (and
        where its companion parts were saved: the description then names those files)."""
        description_json = report.description_json
        for part in report.parts:
            if parts and part.name in parts:
                description_json = description_json.replace(
                    json.dumps(part.file_name), json.dumps(os.path.basename(parts[part.name])))
        return cls(path=path, parts=dict(parts or {}), format=format_name(fmt), file_name=report.file_name,
                   bytes=report.bytes, summary=report.summary, rows=report.rows,
                   cells=report.cells, filled_cells=report.filled_cells,
                   unfilled_cells=report.unfilled_cells,
                   unfilled_by_status=dict(report.unfilled_by_status),
                   below_horizon_cells=report.below_horizon_cells,
                   clamped_cells=report.clamped_cells,
                   skipped_readings=report.skipped_readings,
                   first_skip_reason=report.first_skip_reason, shape=tuple(report.shape),
                   description=(json.loads(description_json) if description_json else None),
                   warnings=list(report.warnings),
                   fill=(_fill_counts(report.fill) if report.HasField("fill") else None))


def _fill_counts(fill: Any) -> Dict[str, Any]:
    """ExportFillCounts → the dict ExportResult.fill documents."""
    return {"policy": fill.policy, "interpolated": fill.interpolated,
            "fallback": fill.fallback, "model": fill.model, "empty": fill.empty,
            "model_fraction": fill.model_fraction}
