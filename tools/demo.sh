#!/usr/bin/env bash
# Sets up (Debian packages), builds nimbus in Release and renders the default demo scene to
# demo.exr and demo.png in the current directory.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/tools/setup.sh"
bash "$root/tools/configure.sh" release
cmake --build "$root/build" -j"$(nproc)" --target nimbus
"$root/build/nimbus" render "$root/scenes/demo.json" -o demo.exr -o demo.png "$@"
