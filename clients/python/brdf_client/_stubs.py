"""Finds (and if needed generates) the protobuf/gRPC stubs of brdfd's API.

The stubs are generated from the repository's proto/ by ../generate_stubs.sh with Debian's protoc
and grpc_python_plugin, into a cache or build directory; they are never committed, because they
must match the protobuf runtime installed next to the protoc that made them (Debian 12: protoc
3.21 and python3-protobuf 3.21, whose Python package reports version 4.21).

Where they go, first match wins:
  1. $BRDF_PY_STUBS (CMake's target brdf_python_stubs writes build/clients/python/stubs),
  2. ${XDG_CACHE_HOME:-~/.cache}/brdf_client/stubs.
When the repository's proto/ (or an installed share/brdfd/proto/, see deploy/CMakeLists.txt) is
present the script is run on import: it is a no-op while the .proto files are unchanged and
regenerates them when they change. Without proto/ (a copied client) the directory must already
hold the stubs.
"""

import os
import pathlib
import subprocess
import sys

_PACKAGE_DIR = pathlib.Path(__file__).resolve().parent
_SCRIPT = _PACKAGE_DIR.parent / "generate_stubs.sh"


def stubs_dir():
    """The directory the stubs are (to be) generated into."""
    explicit = os.environ.get("BRDF_PY_STUBS")
    if explicit:
        return pathlib.Path(explicit)
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(cache) / "brdf_client" / "stubs"


def _proto_root():
    """$BRDF_PROTO_ROOT, else the repository's proto/ (clients/python/brdf_client → ../../../proto),
    else an installed layout's (cmake --install: share/brdfd/python/brdf_client →
    share/brdfd/proto)."""
    explicit = os.environ.get("BRDF_PROTO_ROOT")
    if explicit:
        return pathlib.Path(explicit)
    repository = _PACKAGE_DIR.parent.parent.parent / "proto"
    installed = _PACKAGE_DIR.parent.parent / "proto"
    if not (repository / "brdf" / "v1").is_dir() and (installed / "brdf" / "v1").is_dir():
        return installed
    return repository


def _ensure_generated(out):
    if (_proto_root() / "brdf" / "v1").is_dir() and _SCRIPT.is_file():
        env = dict(os.environ, BRDF_PROTO_ROOT=str(_proto_root()))
        done = subprocess.run(["bash", str(_SCRIPT), str(out)], env=env, capture_output=True,
                              text=True, check=False)
        if done.returncode != 0:
            raise ImportError(
                f"brdf_client: generating the gRPC stubs into {out} failed "
                f"({_SCRIPT} exited {done.returncode}): {done.stderr.strip()}")
    elif not (out / "brdf" / "v1" / "brdf_pb2.py").is_file():
        raise ImportError(
            f"brdf_client: no gRPC stubs in {out} and no proto/ to generate them from "
            f"(looked in {_proto_root()}); run clients/python/generate_stubs.sh {out} in a "
            f"checkout of brdfd, or set BRDF_PY_STUBS to a directory holding brdf/v1/*_pb2.py")


def load():
    """Returns (brdf_pb2, brdf_pb2_grpc, plan_pb2), generating the stubs first when needed."""
    out = stubs_dir()
    _ensure_generated(out)
    if str(out) not in sys.path:
        sys.path.insert(0, str(out))
    try:
        from brdf.v1 import brdf_pb2, brdf_pb2_grpc, plan_pb2  # pylint: disable=import-outside-toplevel
    except ImportError as e:
        raise ImportError(
            f"brdf_client: cannot import the stubs from {out}: {e}. Python's gRPC and protobuf "
            f"come from Debian: sudo apt-get install python3-grpcio python3-protobuf "
            f"(and run with /usr/bin/python3 if another python3 comes first on PATH)") from e
    return brdf_pb2, brdf_pb2_grpc, plan_pb2


brdf_pb2, brdf_pb2_grpc, plan_pb2 = load()
