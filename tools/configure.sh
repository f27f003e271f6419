#!/usr/bin/env bash
# Configures a build tree as the project's scripts build it (docs/testing.md, "How CI's time is
# spent"), so that the demo, the test suite and the fuzzers share one definition of each build:
#   tools/configure.sh release  [DIR]   Release, g++                       (default DIR: build)
#   tools/configure.sh sanitize [DIR]   clang, ASan + UBSan, the fuzzers   (default DIR: build-sanitize)
# A new tree uses Ninja, which compiles a target's sources while its dependencies still build
# (Make waits for each whole target); a tree configured before keeps its generator. Both link
# with lld (a third of the default linker's time on the test binary). Extra arguments after DIR
# go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
kind=${1:?"usage: tools/configure.sh release|sanitize [DIR] [CMAKE ARGS...]"}
case $kind in
  release)
    dir=${2:-build}
    # Debian's interpreter, which has python3-numpy and pytest, for the Python module
    # (docs/python.md) and the viewer's browser tests (both builds).
    args=(-DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=/usr/bin/python3)
    ;;
  sanitize)
    dir=${2:-build-sanitize}
    # Line tables are all that a sanitizer's report needs. Spectral mode is built for 4 and 8
    # wavelengths only (8 is the default): the counts share one template, and the Release build
    # runs every count. No benchmarks. Batches of 16 sources (8 in Release, where an edit should
    # recompile little): a tree that CI builds once (docs/testing.md).
    args=(-DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo
      "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG"
      -DNIMBUS_SANITIZE=ON -DNIMBUS_BUILD_FUZZER=ON -DNIMBUS_BUILD_BENCH=OFF -DNIMBUS_UNITY_BATCH=16
      "-DNIMBUS_WAVELENGTH_COUNTS=4;8" -DPython3_EXECUTABLE=/usr/bin/python3)
    ;;
  *)
    echo "tools/configure.sh: unknown build \"$kind\" (release or sanitize)" >&2
    exit 2
    ;;
esac
shift $(($# < 2 ? $# : 2))
generator=()
[ -f "$dir/CMakeCache.txt" ] || generator=(-G Ninja)
cmake -S . -B "$dir" "${generator[@]}" "${args[@]}" -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld "$@" \
  >/dev/null
