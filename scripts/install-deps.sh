#!/usr/bin/env bash
# Installs the Debian packages CoReDEM builds and runs with (README.md).
# Idempotent: packages already present are left alone, and `apt-get update` runs
# at most once, only when something has to be installed.
#
# Usage: scripts/install-deps.sh [--with-peers]
#   --with-peers   also install the peer codes used by bench/ (liggghts)
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  libzmq3-dev cppzmq-dev libprotobuf-dev protobuf-compiler
  libhdf5-dev hdf5-tools libyaml-cpp-dev libspdlog-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev libsqlite3-dev
  # GoogleTest as a source tree: the DEM core built alone (tests/integration/core-build, gpu-check)
  googletest
  openfoam
  python3 python3-matplotlib python3-h5py python3-zmq python3-protobuf python3-yaml
  # the generators of the tests' reference values (tests/unit/thermochem/reference)
  python3-mpmath
  # coredem render and the ParaView e2e tests (pvbatch on a private Xvfb)
  paraview python3-paraview xvfb
  # used by scripts/openfoam-headers.sh to fetch Debian's OpenFOAM sources
  dpkg-dev bzip2 ca-certificates
  # the committed .clang-format is enforced by scripts/check-format.sh (CI)
  clang-format
  # ip netns / veth of the remote-DEM e2e test and bench/remote/link.sh
  iproute2
  # campaigns on Slurm: the e2e tests start their own single-node Slurm (tests/e2e/slurm)
  slurm-wlm munge
)
if [[ "${1:-}" == "--with-peers" ]]; then
  packages+=(liggghts openmpi-bin)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} Debian packages are present"
  exit 0
fi

echo "install-deps: missing Debian packages: ${missing[*]}"
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    SUDO=(sudo -n)
  else
    echo "install-deps: error: installing packages needs root." >&2
    echo "  Run as root:  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    echo "  then run this command again." >&2
    exit 1
  fi
else
  SUDO=()
fi

export DEBIAN_FRONTEND=noninteractive
echo "install-deps: apt-get update"
"${SUDO[@]}" apt-get update -qq
echo "install-deps: apt-get install ${missing[*]}"
"${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
