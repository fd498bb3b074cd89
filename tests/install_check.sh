#!/usr/bin/env bash
# The install and the Debian package, as a user gets them (test install.*; label install, in the
# default suite): `cmake --install` into a fresh prefix gives a `runout` that runs from there, the
# bundled scenarios, the docs, the QGIS provider and a Python client that /usr/bin/python3 imports
# with no package index (its gRPC modules generated into the build folder); nothing is written into
# the source tree; `cpack -G DEB` gives a package with the program and its library dependencies.
# Usage: install_check.sh BUILD_DIR SOURCE_DIR [deb]
set -euo pipefail
build=$1 src=$2 what=${3:-install}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "install_check: $*" >&2; exit 1; }
before=$(git -C "$src" status --porcelain --untracked-files=all -- clients scenarios docs 2>/dev/null || true)
if [ "$what" = install ]; then
  cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install failed"; }
  p=$tmp/prefix
  [ -x "$p/bin/runout" ] || fail "no bin/runout"
  PATH="$p/bin:/usr/bin:/bin" runout --help > "$tmp/help.txt" || fail "the installed runout --help failed"
  grep -q "depth-averaged" "$tmp/help.txt" || fail "the installed runout's help does not name the engines"
  for f in share/runout/scenarios/in-den-arelen.json share/runout/scenarios/data/arelen/davos_srtm3.tif share/doc/runout/README.md \
           share/doc/runout/user/outputs.md; do
    [ -f "$p/$f" ] || fail "missing $f"
  done
  if [ -d "$src/clients/qgis/runout_provider" ]; then [ -f "$p/share/runout/qgis/runout_provider/metadata.txt" ] || fail "no QGIS provider"; fi
  # The installed program runs the installed scenario (a 30 m variant, for time) from any folder.
  ( cd "$tmp" && PATH="$p/bin:/usr/bin:/bin" runout run "$p/share/runout/scenarios/in-den-arelen-30m.json" --out "$tmp/run" --quiet ) \
    > "$tmp/run.log" 2>&1 || { cat "$tmp/run.log"; fail "the installed runout could not run the installed scenario"; }
  [ -f "$tmp/run/max_depth.tif" ] || fail "the installed run wrote no max_depth.tif"
  # The Python client, alone (its component) into another prefix, imported by Debian's python3.
  cmake --install "$build" --prefix "$tmp/py" --component python_client > /dev/null
  PYTHONPATH="$tmp/py/lib/python3/dist-packages" /usr/bin/python3 -B -c "
import runout_client, runout_client._proto.service_pb2_grpc as s
assert runout_client.__file__.startswith('$tmp/py/'), runout_client.__file__
assert hasattr(runout_client, 'Client') and hasattr(s, 'RunoutStub')
print('runout_client from', runout_client.__file__)" || fail "the installed Python client does not import"
  [ ! -e "$tmp/py/bin/runout" ] || fail "the python_client component installed the program too"
else
  command -v cpack > /dev/null || fail "no cpack"
  ( cd "$tmp" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$tmp/pkg" > "$tmp/cpack.log" 2>&1 ) || { cat "$tmp/cpack.log"; fail "cpack failed"; }
  deb=$(ls "$tmp"/pkg/*.deb | head -1)
  [ -n "$deb" ] || fail "cpack made no .deb"
  dpkg-deb -c "$deb" > "$tmp/contents.txt"
  for f in ./usr/bin/runout ./usr/share/runout/scenarios/in-den-arelen.json ./usr/lib/python3/dist-packages/runout_client/client.py \
           ./usr/lib/python3/dist-packages/runout_client/_proto/service_pb2_grpc.py; do
    grep -q " $f\$" "$tmp/contents.txt" || fail "the package lacks $f"
  done
  depends=$(dpkg-deb -f "$deb" Depends)
  for d in libgdal libgrpc python3-grpcio; do
    echo "$depends" | grep -q "$d" || fail "the package's Depends lack $d: $depends"
  done
  echo "$(basename "$deb"): $(stat -c %s "$deb") bytes; Depends: $depends"
fi
after=$(git -C "$src" status --porcelain --untracked-files=all -- clients scenarios docs 2>/dev/null || true)
[ "$before" = "$after" ] || fail "the source tree changed: $(diff <(echo "$before") <(echo "$after"))"
echo "install_check: $what ok"
