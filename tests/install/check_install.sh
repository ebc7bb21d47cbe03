#!/usr/bin/env bash
# check_install.sh BUILD_DIR: installs BUILD_DIR into a temporary prefix with `cmake --install`
# and checks the layout a package needs (deploy/CMakeLists.txt lists it). Prints every missing or
# wrong piece and exits 1 if there was any; the prefix is removed afterwards.
set -uo pipefail
build="${1:?usage: check_install.sh BUILD_DIR}"
prefix="$(mktemp -d "${TMPDIR:-/tmp}/brdfd-install.XXXXXX")"
trap 'rm -rf "$prefix"' EXIT
failures=0
fail() {
  echo "check_install: $*" >&2
  failures=$((failures + 1))
}

if ! cmake --install "$build" --prefix "$prefix" >"$prefix.log" 2>&1; then
  cat "$prefix.log" >&2
  rm -f "$prefix.log"
  echo "check_install: cmake --install $build --prefix $prefix failed (is the build complete?)" >&2
  exit 1
fi
rm -f "$prefix.log"

for exe in brdfd brdfctl brdf-sim brdf-interp brdf-export brdf-stage-probe; do
  if [[ ! -x "$prefix/bin/$exe" ]]; then
    fail "bin/$exe is missing or not executable"
  elif ! "$prefix/bin/$exe" --help >/dev/null 2>&1; then
    fail "bin/$exe --help failed: the installed executable does not run"
  fi
done

unit="$prefix/lib/systemd/system/brdfd.service"
if [[ ! -f "$unit" ]]; then
  fail "lib/systemd/system/brdfd.service is missing"
else
  grep -q "^ExecStart=$prefix/bin/brdfd --config /etc/brdfd/brdfd.toml$" "$unit" ||
    fail "the unit's ExecStart does not run the installed brdfd: $(grep '^ExecStart=' "$unit")"
  for key in Type=notify User=brdfd StateDirectory=brdfd ConfigurationDirectory=brdfd \
    ProtectSystem=strict NoNewPrivileges=yes SupplementaryGroups=dialout; do
    grep -q "^$key$" "$unit" || fail "the unit lacks $key"
  done
  if command -v systemd-analyze >/dev/null; then
    out="$(systemd-analyze verify "$unit" 2>&1)" || fail "systemd-analyze verify: $out"
    [[ -z "$out" ]] || fail "systemd-analyze verify complains: $out"
  fi
fi

grep -q '^u *brdfd ' "$prefix/lib/sysusers.d/brdfd.conf" 2>/dev/null ||
  fail "lib/sysusers.d/brdfd.conf is missing or does not create the brdfd user"
grep -q 'SYMLINK+="pr650"' "$prefix/lib/udev/rules.d/99-brdf-pr650.rules" 2>/dev/null ||
  fail "lib/udev/rules.d/99-brdf-pr650.rules is missing or has no pr650 symlink"

doc="$prefix/share/doc/brdfd"
grep -q '^\[meter\]' "$doc/brdfd.example.toml" 2>/dev/null ||
  fail "share/doc/brdfd/brdfd.example.toml is missing"
[[ -f "$doc/README.md" ]] || fail "share/doc/brdfd/README.md is missing"
for page in README geometry interpolation pr650 stage-modbus; do
  [[ -f "$doc/docs/$page.md" ]] || fail "share/doc/brdfd/docs/$page.md is missing"
done

py="$prefix/share/brdfd/python"
for f in brdf_client/__init__.py brdf_client/client.py examples/quickstart_figures.py \
  generate_stubs.sh README.md; do
  [[ -f "$py/$f" ]] || fail "share/brdfd/python/$f is missing"
done
[[ -f "$prefix/share/brdfd/proto/brdf/v1/brdf.proto" ]] || fail "share/brdfd/proto is missing"
[[ -f "$prefix/share/brdfd/plans/demo.json" ]] || fail "share/brdfd/plans/demo.json is missing"
for profile in az leadshine moons; do
  grep -q "^name = \"$profile\"" "$prefix/share/brdfd/stage-profiles/$profile.toml" 2>/dev/null ||
    fail "share/brdfd/stage-profiles/$profile.toml is missing"
done
for material in paint glossy brushed gold; do
  [[ -f "$prefix/share/brdfd/materials/$material.toml" ]] ||
    fail "share/brdfd/materials/$material.toml is missing"
done
if [[ -x /usr/bin/python3 ]] && command -v grpc_python_plugin >/dev/null; then
  # The installed client generates its stubs from the installed .proto files and imports.
  out="$(cd / && BRDF_PY_STUBS="$prefix/stubs" /usr/bin/python3 -c "
import sys; sys.path.insert(0, '$py')
import brdf_client
from brdf_client import _stubs
assert hasattr(_stubs.brdf_pb2_grpc, 'DataStub')
print('ok')" 2>&1)"
  [[ "$out" == ok ]] || fail "the installed Python client does not import: $out"
fi

if [[ $failures -gt 0 ]]; then
  echo "check_install: $failures problem(s) in the installed layout" >&2
  exit 1
fi
echo "check_install: the layout under a temporary prefix is complete"
