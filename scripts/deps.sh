# Sourced by scripts/test and scripts/demo: installs the Debian packages the build needs, if missing,
# then configures and builds into build/. Idempotent.
set -euo pipefail

RUNOUT_PACKAGES=(
  cmake g++ make ninja-build pkg-config
  libgdal-dev gdal-bin libproj-dev proj-bin
  petsc-dev libhdf5-openmpi-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libsqlite3-dev libssl-dev openssl
  libcairo2-dev libpango1.0-dev fonts-dejavu-core
  python3-grpcio python3-protobuf
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev
  munge slurmctld slurmd slurm-client
)

runout_install_deps() {
  local missing=()
  for p in "${RUNOUT_PACKAGES[@]}"; do
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
