#!/usr/bin/env bash
# Installs exactly the Debian 12 packages brdfd needs to build, test and run. Idempotent: packages
# already present are left alone and apt is not touched at all when nothing is missing.
# Uses sudo only when not root. Usage: deploy/install-deps.sh [--with-extras]
#   --with-extras  also the tools for fuzzing and benchmarks against scipy (clang, scipy).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  clang-format # tests: the sources as .clang-format lays them out (tools/check/format.py)
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  libserialport-dev libmodbus-dev libspdlog-dev libfmt-dev libsqlite3-dev sqlite3
  libqhull-dev libcgal-dev libtomlplusplus-dev libcli11-dev libsystemd-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-numpy python3-grpcio python3-protobuf python3-serial
  python3-scipy python3-matplotlib colord-data
  python3-pandas python3-xarray python3-tqdm python3-netcdf4 python3-venv python3-pip python3-setuptools python3-ipykernel python3-nbclient python3-nbformat mypy # clients/python: labelled data, install, notebook, types
  python3-jsonschema # tests: the BiRD export checked against its required fields (docs/bird-format.md)
  # the lab archive: libpq for brdfd and brdf-archive; the server and psql for its tests
  libpq-dev postgresql-15 postgresql-client-15
  # the web console: its HTTP server, and the browser its tests drive
  libcpp-httplib-dev chromium
)
# The web console's build needs node and npm; Debian's nodejs and npm unless a node is already
# installed (another distribution of node, e.g. NodeSource's, brings its own npm and conflicts
# with Debian's npm package).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  packages+=(nodejs npm)
fi
if [[ "${1:-}" == "--with-extras" ]]; then
  packages+=(clang-14 libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  if ! command -v sudo >/dev/null; then
    echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
    exit 1
  fi
  SUDO="sudo"
fi
echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
