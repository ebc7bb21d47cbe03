"""NetCDF files of the labelled structures, written by xarray's own writer (Dataset.to_netcdf).

    brdf_client.write_netcdf(grid, "grid.nc")      # or brdf.grid(..., netcdf="grid.nc")
    xarray.open_dataset("grid.nc")                  # the same Dataset back

NetCDF attributes hold strings and numbers only: booleans become 0 / 1 and anything else
(lists of strings, dicts) JSON text; variables are written as they are. The engine is netCDF4
(Debian's python3-netcdf4: NetCDF-4/HDF5, UTF-8 strings) when installed, else scipy's NetCDF-3
writer (python3-scipy), which xarray also reads back.
"""

import json
import os
from typing import Any, Dict, Optional


def default_engine() -> str:
    """"netcdf4" when the netCDF4 module is importable, else "scipy"."""
    try:
        import netCDF4  # noqa: F401  pylint: disable=import-outside-toplevel,unused-import
    except ImportError:
        return "scipy"
    return "netcdf4"


def _clean_attrs(attrs: Dict[str, Any]) -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    for key, value in attrs.items():
        if value is None:
            continue
        if isinstance(value, bool):
            out[key] = int(value)
        elif isinstance(value, (str, int, float)):
            out[key] = value
        elif isinstance(value, (list, tuple)) and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            out[key] = list(value)
        else:
            out[key] = json.dumps(value, ensure_ascii=False, default=str)
    return out


def netcdf_ready(obj: Any) -> Any:
    """A copy of a Dataset (or DataArray, as a Dataset) whose attrs NetCDF can hold."""
    ds = obj.to_dataset() if hasattr(obj, "to_dataset") and not hasattr(obj, "data_vars") else obj
    ds = ds.copy()
    ds.attrs = _clean_attrs(dict(ds.attrs))
    for name in list(ds.variables):
        ds[name].attrs = _clean_attrs(dict(ds[name].attrs))
    return ds


def write_netcdf(obj: Any, path: "str | os.PathLike[str]", engine: Optional[str] = None) -> str:
    """Writes a Dataset or DataArray of this client to `path` with xarray's writer; returns the
    path. engine: "netcdf4" or "scipy"; None: default_engine()."""
    path = os.fspath(path)
    netcdf_ready(obj).to_netcdf(path, engine=engine or default_engine())
    return path
