#!/bin/bash
# nimbus against pbrt-v4 on the same scenes (issue 13), one thread each, 64 x 64 pixels:
# time, MSE against each renderer's converged reference, efficiency 1/(MSE * time), and how
# well the two renderers' references agree. The scenes in pbrt-v4's format are bench/pbrt/*.pbrt;
# the driver is bench/pbrt/side_by_side.py; docs/benchmarks.md, "Against pbrt-v4", has the
# method and the current table, docs/benchmarks/pbrt-v4.md every run and the conventions matched.
#
#   PBRT=/path/to/pbrt bash bench/pbrt_side_by_side.sh [options] [scene...]
#
# Environment:
#   PBRT      a pbrt-v4 binary (CPU build). Unset or empty: prints why and exits 0 (skipped),
#             so the script may sit among other benchmarks. Set but not a pbrt-v4 binary: exit 2.
#   NIMBUS    the nimbus binary (default: build-pbrtbench/nimbus, else build/nimbus)
#   VDB_TOOL  OpenVDB's vdb_tool, which converts the cloud's grid to NanoVDB for pbrt
#             (default: vdb_tool on PATH; Debian: apt-get install libopenvdb-tools)
#   OUT       work and cache folder (default: build-pbrtbench/pbrt-side-by-side): staged scenes,
#             the generated grids, cached references (refs/), images (tmp/)
# Options (passed to the driver): --spp N (64), --ref-spp N (4096), --reps N (5),
#   --ref-threads N (all cores), --voxel-size H (1/64), --json FILE; scenes: cloud, cloud-grid,
#   marble, skin, marble-sun, rough-marble, rough-gold (default: all).
#   --manifold-off (off by default): also run nimbus with manifold next-event estimation off
#   (--set integrator.manifold=false, rgb and spectral 4, spectral MIS) on every scene run. That
#   render setting comes with issue 41; a nimbus without it rejects the key and the run stops.
# Exit status: 0 done or skipped (PBRT unset), 2 bad setup, 1 a render failed.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

if [[ -z "${PBRT:-}" ]]; then
  echo "pbrt_side_by_side: skipped: set PBRT to a pbrt-v4 binary (a CPU build of github.com/mmp/pbrt-v4)" >&2
  exit 0
fi
if [[ ! -x "$PBRT" ]]; then
  echo "pbrt_side_by_side: PBRT=$PBRT is not an executable file" >&2
  exit 2
fi
if ! "$PBRT" --help 2>&1 | grep -q -- "--wavefront"; then
  echo "pbrt_side_by_side: PBRT=$PBRT does not look like pbrt-v4 (its --help has no --wavefront)" >&2
  exit 2
fi

nimbus=${NIMBUS:-}
if [[ -z "$nimbus" ]]; then
  for c in "$repo/build-pbrtbench/nimbus" "$repo/build/nimbus"; do
    [[ -x "$c" ]] && { nimbus=$c; break; }
  done
fi
if [[ -z "$nimbus" || ! -x "$nimbus" ]]; then
  echo "pbrt_side_by_side: no nimbus binary: build it (cmake --build build --target nimbus) or set NIMBUS" >&2
  exit 2
fi
# The driver runs the renderers from its work folder: relative paths would not resolve there.
nimbus=$(realpath "$nimbus")
PBRT=$(realpath "$PBRT")

vdb_tool=${VDB_TOOL:-vdb_tool}
if ! command -v "$vdb_tool" >/dev/null; then
  echo "pbrt_side_by_side: $vdb_tool not found (Debian: apt-get install libopenvdb-tools), or set VDB_TOOL" >&2
  exit 2
fi
python=/usr/bin/python3
if ! "$python" -c "import numpy" 2>/dev/null; then
  echo "pbrt_side_by_side: $python with numpy is needed (Debian: apt-get install python3-numpy)" >&2
  exit 2
fi

out=${OUT:-$repo/build-pbrtbench/pbrt-side-by-side}
mkdir -p "$out"

# The EXR reader: a one-file program against the system's OpenEXR (libopenexr-dev).
conv="$out/exr_to_pfm"
src="$repo/bench/pbrt/exr_to_pfm.cpp"
if [[ ! -x "$conv" || "$src" -nt "$conv" ]]; then
  # shellcheck disable=SC2046
  g++ -O2 -std=c++17 "$src" -o "$conv" $(pkg-config --cflags --libs OpenEXR) || {
    echo "pbrt_side_by_side: could not build $src (needs g++ and libopenexr-dev)" >&2
    exit 2
  }
fi

echo "pbrt-v4: $PBRT" >&2
echo "nimbus:  $nimbus ($("$nimbus" --version 2>&1 | head -1))" >&2
exec "$python" "$repo/bench/pbrt/side_by_side.py" --pbrt "$PBRT" --nimbus "$nimbus" \
  --vdb-tool "$vdb_tool" --exr-to-pfm "$conv" --out "$out" "$@"
