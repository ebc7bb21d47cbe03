#!/usr/bin/env bash
# Generates the Python protobuf and gRPC stubs of brdfd's API (proto/brdf/v1/*.proto) with
# Debian's protoc and grpc_python_plugin (packages protobuf-compiler, protobuf-compiler-grpc).
#
#   clients/python/generate_stubs.sh [OUT_DIR]
#
# OUT_DIR defaults to $BRDF_PY_STUBS, else ${XDG_CACHE_HOME:-~/.cache}/brdf_client/stubs. The stubs
# land in OUT_DIR/brdf/v1/{brdf,plan}_pb2{,_grpc}.py; put OUT_DIR on sys.path to import them as
# `from brdf.v1 import brdf_pb2` (brdf_client does this for you). Generated code is never
# committed: it depends on the protoc that made it.
#
# Idempotent: OUT_DIR/.stamp holds a hash of the .proto files and of the compiler and plugin; when
# it matches, nothing is done. Otherwise the stubs are generated into a temporary directory and
# swapped in under a lock, so concurrent runs (parallel tests) never see half-written files.
# Environment: BRDF_PROTO_ROOT (default: the repository's proto/), PROTOC, GRPC_PYTHON_PLUGIN.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
proto_root="${BRDF_PROTO_ROOT:-$here/../../proto}"
out="${1:-${BRDF_PY_STUBS:-${XDG_CACHE_HOME:-$HOME/.cache}/brdf_client/stubs}}"
protoc="${PROTOC:-$(command -v protoc || true)}"
plugin="${GRPC_PYTHON_PLUGIN:-$(command -v grpc_python_plugin || true)}"

fail() {
  echo "generate_stubs: $*" >&2
  exit 1
}
[[ -n "$protoc" && -x "$protoc" ]] ||
  fail "protoc not found; install it with: sudo apt-get install protobuf-compiler"
[[ -n "$plugin" && -x "$plugin" ]] ||
  fail "grpc_python_plugin not found; install it with: sudo apt-get install protobuf-compiler-grpc"
[[ -d "$proto_root/brdf/v1" ]] ||
  fail "no .proto files under $proto_root/brdf/v1; set BRDF_PROTO_ROOT to the repository's proto/"

proto_root="$(cd "$proto_root" && pwd)"
mapfile -t protos < <(cd "$proto_root" && find brdf -name '*.proto' | LC_ALL=C sort)
[[ ${#protos[@]} -gt 0 ]] || fail "no .proto files under $proto_root/brdf"

# What the stubs depend on: every .proto (name and content), the compiler and the plugin.
stamp="$(
  {
    "$protoc" --version
    sha256sum "$plugin" | cut -d' ' -f1
    for p in "${protos[@]}"; do
      echo "$p"
      sha256sum "$proto_root/$p" | cut -d' ' -f1
    done
  } | sha256sum | cut -d' ' -f1
)"

mkdir -p "$(dirname "$out")"
out="$(cd "$(dirname "$out")" && pwd)/$(basename "$out")"
exec 9>"$out.lock"
flock 9

if [[ -f "$out/.stamp" && "$(cat "$out/.stamp")" == "$stamp" ]]; then
  exit 0
fi

tmp="$(mktemp -d "$out.tmp.XXXXXX")"
chmod 755 "$tmp"
trap 'rm -rf "$tmp"' EXIT
(cd "$proto_root" && "$protoc" --proto_path=. \
  --python_out="$tmp" --grpc_python_out="$tmp" \
  --plugin=protoc-gen-grpc_python="$plugin" "${protos[@]}") ||
  fail "protoc failed on $proto_root (see above)"
echo "$stamp" >"$tmp/.stamp"
rm -rf "$out"
mv "$tmp" "$out"
trap - EXIT
echo "generate_stubs: wrote $out/brdf ($("$protoc" --version), ${#protos[@]} .proto files)" >&2
