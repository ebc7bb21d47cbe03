"""brdf_client: Python access to brdfd, the spectral BRDF measurement daemon, for scripts and
notebooks. Hands back labelled data (pandas, xarray) as well as NumPy arrays.

    from brdf_client import BrdfClient
    with BrdfClient("127.0.0.1:50051", token="...") as brdf:
        data = brdf.load_readings(session_id)            # ReadingSet (NumPy columns)
        df = data.to_dataframe()                          # one row per reading (pandas)
        spectra = data.to_dataarray("brdf")               # reading × wavelength (xarray), sr⁻¹
        grid = brdf.grid(session_id, step=5)              # xarray Dataset (θi, θo, φ, λ)
        r = brdf.interpolate(session_id, 30, 40, 160)     # one spectrum, .to_dataset()
        brdf.export(session_id, "merl", "sample.binary")  # a file for a renderer
    python3 -m brdf_client --version                      # this client and the API it speaks
    python3 -m brdf_client.figures --address ... --token ... --session ID --out DIR

Install: pip install --no-build-isolation --no-deps ./clients/python (README.md). The gRPC stubs
are generated at install time, or on first import (see _stubs.py). grpcio, protobuf, NumPy,
pandas, xarray, tqdm and matplotlib come from Debian (python3-grpcio, python3-protobuf,
python3-numpy, python3-pandas, python3-xarray, python3-tqdm, python3-matplotlib).

Modules: client (BrdfClient), errors (BrdfError and one subclass per status code), readings
(ReadingSet), reading_tables (pandas / xarray of readings), interpolation (InterpolationResult,
InterpolationBatch), interp_datasets, grid_datasets (open_grid), grid_calls, angles (half /
difference angles), labels (dimension names and units), netcdf (write_netcdf), progress (tqdm),
spectra (reflectance/BRDF of stored readings), events (Event), export (ExportResult), plans,
names (enum names), figures (the paper's figures).
"""

from typing import Dict

from ._version import PROTO_PACKAGE, __version__
from ._stubs import brdf_pb2, plan_pb2, proto_digest, stubs_dir
from .angles import half_diff_from_incidence, incidence_from_half_diff
from .client import BrdfClient
from .errors import (BrdfError, Cancelled, DataLoss, DeadlineExceeded, FailedPrecondition,
                     InvalidArgument, NotFound, PermissionDenied, Unauthenticated, Unavailable)
from .events import Event
from .export import ExportResult
from .grid_datasets import open_grid
from .interpolation import (InterpolationBatch, InterpolationResult, InterpolationUncertainty,
                            Vertex)
from .netcdf import write_netcdf
from .plans import to_plan
from .readings import ReadingSet, UncertaintyBudget, UncertaintyComponent
from .queries import candidate_queries, pick_query
from .spectra import reading_spectrum, vertex_spectra


def about() -> Dict[str, str]:
    """This client's version, the API it speaks (protobuf package and the SHA-256 of its .proto
    files, first 12 hex digits) and where its stubs are."""
    return {"version": __version__, "proto_package": PROTO_PACKAGE,
            "proto_digest": proto_digest(), "stubs": str(stubs_dir())}


__all__ = [
    "BrdfClient", "BrdfError", "Cancelled", "DataLoss", "DeadlineExceeded", "Event",
    "ExportResult", "FailedPrecondition", "InterpolationBatch", "InterpolationResult",
    "InterpolationUncertainty",
    "InvalidArgument", "NotFound", "PROTO_PACKAGE", "PermissionDenied", "ReadingSet",
    "candidate_queries", "pick_query",
    "UncertaintyBudget", "UncertaintyComponent",
    "Unauthenticated", "Unavailable", "Vertex", "__version__", "about", "brdf_pb2",
    "half_diff_from_incidence", "incidence_from_half_diff", "open_grid", "plan_pb2",
    "reading_spectrum", "to_plan", "vertex_spectra", "write_netcdf",
]
