#!/usr/bin/env bash
# Checks that the committed spectral tables (data/spectral_tables.tar.xz) hold the file that the
# build generates: exit 0 if identical, else 1 with what to run.
#   tools/check_spectral_tables.sh ARCHIVE GENERATED_FILE
set -euo pipefail
archive=$(realpath "$1")
generated=$2
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
(cd "$scratch" && cmake -E tar xJf "$archive")
if ! cmp -s "$scratch/spectral_tables.cpp" "$generated"; then
  echo "$archive differs from the generated $generated:" \
    "run cmake --build <build> --target update_spectral_tables" >&2
  exit 1
fi
