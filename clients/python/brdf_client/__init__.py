"""brdf_client: Python access to brdfd, the spectral BRDF measurement daemon.

    from brdf_client import BrdfClient, BrdfError
    brdf = BrdfClient("127.0.0.1:50051", token="...")
    data = brdf.load_readings(session_id)                  # raw readings as NumPy arrays
    r = brdf.interpolate(session_id, 30, 40, 160)            # spectrum between the samples
    brdf.export(session_id, "merl", "sample.binary")         # a file for a renderer
    python3 -m brdf_client.figures --address ... --token ... --session ID --out DIR

The gRPC stubs are generated from the repository's proto/ on first import (see _stubs.py).
Python's grpcio, protobuf, NumPy and matplotlib come from Debian (python3-grpcio,
python3-protobuf, python3-numpy, python3-matplotlib).

Modules: client (BrdfClient), errors (BrdfError), readings (ReadingSet), interpolation
(InterpolationResult, InterpolationBatch), spectra (reflectance/BRDF of stored readings),
events (Event), export (ExportResult), plans (plan dicts and files), names (enum names), figures (the paper's figures).
"""

from ._stubs import brdf_pb2, plan_pb2
from .client import BrdfClient
from .errors import BrdfError
from .events import Event
from .export import ExportResult
from .interpolation import InterpolationBatch, InterpolationResult, Vertex
from .plans import to_plan
from .readings import ReadingSet
from .spectra import reading_spectrum, vertex_spectra

__all__ = [
    "BrdfClient", "BrdfError", "Event", "ExportResult", "InterpolationBatch", "InterpolationResult", "ReadingSet",
    "Vertex", "brdf_pb2", "plan_pb2", "reading_spectrum", "to_plan", "vertex_spectra",
]
