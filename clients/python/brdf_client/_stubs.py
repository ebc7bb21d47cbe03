"""Finds (and if needed generates) the protobuf/gRPC stubs of brdfd's API.

The stubs are generated from the API's .proto files by generate_stubs.sh with Debian's protoc
and grpc_python_plugin; they are never committed, because they must match the protobuf runtime
installed next to the protoc that made them (Debian 12: protoc 3.21 and python3-protobuf 3.21,
whose Python package reports version 4.21).

Where they are, first match wins:
  1. $BRDF_PY_STUBS (CMake's target brdf_python_stubs writes build/clients/python/stubs),
     generated there on import when a proto/ is at hand;
  2. the installed package's own (brdf_client/_generated/, made by `pip install`: setup.py);
  3. ${XDG_CACHE_HOME:-~/.cache}/brdf_client/stubs, generated there on import.
The .proto files are $BRDF_PROTO_ROOT, else the repository's proto/ (a checkout), else an
installed share/brdfd/proto/ (cmake --install), else the copy inside the installed package.
Generating is a no-op while the .proto files are unchanged and regenerates when they change.
Without any proto/ (a copied client) the directory must already hold the stubs.
"""

import hashlib
import os
import pathlib
import subprocess
import sys
from typing import Any, Optional, Tuple

_PACKAGE_DIR = pathlib.Path(__file__).resolve().parent
# The generator: next to the package in a checkout or share/brdfd/python, inside it when installed.
_SCRIPTS = (_PACKAGE_DIR.parent / "generate_stubs.sh", _PACKAGE_DIR / "generate_stubs.sh")
_BUNDLED = _PACKAGE_DIR / "_generated"


def _script() -> Optional[pathlib.Path]:
    return next((s for s in _SCRIPTS if s.is_file()), None)


def _has_stubs(directory: pathlib.Path) -> bool:
    return (directory / "brdf" / "v1" / "brdf_pb2.py").is_file()


def stubs_dir() -> pathlib.Path:
    """The directory the stubs are (to be) generated into, or come from."""
    explicit = os.environ.get("BRDF_PY_STUBS")
    if explicit:
        return pathlib.Path(explicit)
    if _has_stubs(_BUNDLED):
        return _BUNDLED
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return pathlib.Path(cache) / "brdf_client" / "stubs"


def proto_root() -> pathlib.Path:
    """Where the API's .proto files are: $BRDF_PROTO_ROOT, else the repository's proto/
    (clients/python/brdf_client → ../../../proto), else an installed layout's (cmake --install:
    share/brdfd/python/brdf_client → share/brdfd/proto), else the package's own copy (pip)."""
    explicit = os.environ.get("BRDF_PROTO_ROOT")
    if explicit:
        return pathlib.Path(explicit)
    candidates = (_PACKAGE_DIR.parent.parent.parent / "proto", _PACKAGE_DIR.parent.parent / "proto",
                  _PACKAGE_DIR / "proto")
    for candidate in candidates:
        if (candidate / "brdf" / "v1").is_dir():
            return candidate
    return candidates[0]


def proto_digest() -> str:
    """SHA-256 of the API's .proto files (their names and contents, sorted), the first 12 hex
    digits: two clients with the same digest speak exactly the same API. "" without proto/."""
    root = proto_root() / "brdf" / "v1"
    files = sorted(root.glob("*.proto")) if root.is_dir() else []
    if not files:
        return ""
    h = hashlib.sha256()
    for f in files:
        h.update(f"brdf/v1/{f.name}\n".encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def _ensure_generated(out: pathlib.Path) -> None:
    root, script = proto_root(), _script()
    if out == _BUNDLED:
        return  # made at install time from the package's own .proto files
    if (root / "brdf" / "v1").is_dir() and script is not None:
        env = dict(os.environ, BRDF_PROTO_ROOT=str(root))
        done = subprocess.run(["bash", str(script), str(out)], env=env, capture_output=True,
                              text=True, check=False)
        if done.returncode != 0:
            raise ImportError(
                f"brdf_client: generating the gRPC stubs into {out} failed "
                f"({script} exited {done.returncode}): {done.stderr.strip()}")
    elif not _has_stubs(out):
        raise ImportError(
            f"brdf_client: no gRPC stubs in {out} and no proto/ to generate them from "
            f"(looked in {root}); run clients/python/generate_stubs.sh {out} in a "
            f"checkout of brdfd, or set BRDF_PY_STUBS to a directory holding brdf/v1/*_pb2.py")


def load() -> Tuple[Any, Any, Any]:
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
