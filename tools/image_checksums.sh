#!/usr/bin/env bash
# Renders seven scenes × three tracking modes small and prints one SHA-256 per EXR: a refactor
# must change no pixel (issue 12). `--check FILE` compares with a recorded list instead and
# exits 1 on any difference.
#
# Usage: tools/image_checksums.sh NIMBUS [--check FILE]
set -euo pipefail
nimbus=$1
check=${3:-}
here="$(cd "$(dirname "$0")/.." && pwd)"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
# vdb_cloud and vdb_fire read their grids through the OpenVDB module (media/vdb_module.h).
scenes=(demo freeforms translucent cloud_sunlit spectral vdb_cloud vdb_fire)
modes=(delta spectral-history spectral-mis)
list="$out/checksums.txt"
for scene in "${scenes[@]}"; do
  for mode in "${modes[@]}"; do
    extra=()
    # The paper's method as it is meant to run: weights and decomposition.
    [ "$mode" = spectral-history ] && extra=(--set integrator.absorption=weight --set integrator.decomposition=true)
    "$nimbus" render "$here/scenes/$scene.json" -o "$out/$scene-$mode.exr" -q --spp 2 --seed 3 \
      --set film.width=24 --set film.height=16 --set integrator.tracking="$mode" "${extra[@]}"
    (cd "$out" && sha256sum "$scene-$mode.exr") >> "$list"
  done
done
if [ -n "$check" ]; then
  diff "$check" "$list" && echo "image checksums: all ${#scenes[@]}x${#modes[@]} images unchanged"
else
  cat "$list"
fi
