#!/usr/bin/env bash
# Installs the Debian packages nimbus needs. A no-op when they are present.
set -euo pipefail
packages=(
  # Ninja and lld: the scripts' builds (tools/configure.sh)
  build-essential cmake ninja-build lld pkg-config clang libclang-rt-14-dev
  libtbb-dev libopenexr-dev libpng-dev zlib1g-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # OpenVDB volumes: the library, NanoVDB, Boost.Iostreams for OpenVDB's CMake module, and
  # vdb_print, which the tests run on exported files
  libopenvdb-dev libnanovdb-dev libboost-iostreams-dev libopenvdb-tools
  colord-data python3-numpy python3-matplotlib
  # The Python module (python/, docs/python.md) and its tests
  python3-dev pybind11-dev python3-pytest
  # MPI: `mpirun -np K nimbus render` (README, "Rendering on a cluster")
  libopenmpi-dev openmpi-bin
  # `nimbus view`: its web server, and the browser its tests drive (tests/browser/)
  libmicrohttpd-dev chromium
  # Blender 3.4: the add-on's tests run it headless (tests/blender, docs/blender.md)
  blender
  # Embree 3: bench/embree_bvh, its kernels against our surface hierarchy (docs/benchmarks.md)
  libembree-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing Debian packages: ${missing[*]} (run as root, or install them)" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
