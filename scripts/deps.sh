# Sourced by scripts/test and scripts/demo: installs the Debian packages the build needs (and for
# scripts/test those its tests need), if missing, then configures and builds into build/; installs
# the program (runout_install). Idempotent.
set -euo pipefail

RUNOUT_PACKAGES=(
  cmake g++ make ninja-build pkg-config
  libgdal-dev gdal-bin libproj-dev proj-bin
  petsc-dev libhdf5-openmpi-dev libscotch-dev openmpi-bin
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libsqlite3-dev libssl-dev openssl
  libcairo2-dev libpango1.0-dev fonts-dejavu-core
  python3-grpcio python3-protobuf
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev
)

# What only the tests need besides: a one-node Slurm cluster (the slurm tests), dpkg-shlibdeps for
# the Debian package (install.deb), QGIS for the Processing provider's test, poppler's PDF tools for
# the report's test.
RUNOUT_TEST_PACKAGES=(
  munge slurmctld slurmd slurm-client
  dpkg-dev
  qgis python3-qgis
  poppler-utils
)

# runout_install_deps [test]: the build's packages, and with `test` the tests' too.
runout_install_deps() {
  local missing=() wanted=("${RUNOUT_PACKAGES[@]}")
  if [ "${1:-}" = test ]; then wanted+=("${RUNOUT_TEST_PACKAGES[@]}"); fi
  for p in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  echo "runout: installing missing Debian packages: ${missing[*]}" >&2
  local SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -q
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

runout_build() {
  local root
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE="${RUNOUT_BUILD_TYPE:-Release}" ${RUNOUT_CMAKE_ARGS:-}
  cmake --build "$root/build" --parallel "$(nproc)"
}

# runout_install [PREFIX]: `cmake --install` of the build (default /usr/local, with sudo where the
# prefix is not writable), so that `runout` is on the PATH.
runout_install() {
  local root prefix="${1:-${RUNOUT_PREFIX:-/usr/local}}" SUDO=""
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  mkdir -p "$prefix" 2>/dev/null || true
  if [ ! -w "$prefix" ] && [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO cmake --install "$root/build" --prefix "$prefix" > /dev/null || return 1
  echo "runout: installed $prefix/bin/runout" >&2
}
