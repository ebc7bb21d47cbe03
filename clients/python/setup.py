"""setuptools' build step for brdf_client (the metadata is in pyproject.toml).

build_py also puts into the built package what it needs to speak brdfd's API once installed away
from the repository:
  brdf_client/proto/brdf/v1/*.proto   the API, copied from the repository's proto/;
  brdf_client/generate_stubs.sh       the stub generator (clients/python/generate_stubs.sh);
  brdf_client/_generated/brdf/v1/     the protobuf and gRPC stubs, generated with Debian's protoc
                                      and grpc_python_plugin (protobuf-compiler-grpc).
Without protoc or the plugin the build still succeeds, with a warning: the stubs are then
generated on first import (brdf_client/_stubs.py) from the copied .proto files, once protoc is
installed.
"""

import os
import pathlib
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent


def proto_root():
    """The repository's proto/ (a checkout), else the copy inside an unpacked sdist."""
    for candidate in (HERE.parent.parent / "proto", HERE / "brdf_client" / "proto"):
        if (candidate / "brdf" / "v1").is_dir():
            return candidate
    raise SystemExit(f"brdf_client: no proto/brdf/v1 next to {HERE} (expected the repository's "
                     "proto/); build from a checkout of brdfd")


class BuildWithStubs(build_py):
    """build_py, then the .proto files, the generator and the stubs into the built package."""

    def run(self):
        super().run()
        if self.dry_run:
            return
        package = pathlib.Path(self.build_lib) / "brdf_client"
        source = proto_root()
        protos = package / "proto" / "brdf" / "v1"
        protos.mkdir(parents=True, exist_ok=True)
        for proto in sorted((source / "brdf" / "v1").glob("*.proto")):
            shutil.copy2(proto, protos / proto.name)
        script = package / "generate_stubs.sh"
        shutil.copy2(HERE / "generate_stubs.sh", script)
        out = package / "_generated"
        done = subprocess.run(["bash", str(script), str(out)],
                              env=dict(os.environ, BRDF_PROTO_ROOT=str(package / "proto")),
                              capture_output=True, text=True, check=False)
        (package / "_generated.lock").unlink(missing_ok=True)  # the generator's lock file
        if done.returncode != 0:
            self.warn("brdf_client: the gRPC stubs were not generated at build time "
                      f"({done.stderr.strip()}); they will be generated on first import")


setup(cmdclass={"build_py": BuildWithStubs})
