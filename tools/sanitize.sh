#!/usr/bin/env bash
# The sanitized pass of the test suite (docs/testing.md): builds with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build-sanitize/, runs the suite there, then fuzzes the committed
# corpus for a fixed number of inputs. Assumes tools/setup.sh has run.
#
# Left out here, and run in the Release pass: the packaging test (the example it builds is not
# instrumented); the render tests whose instances repeat, on costlier scenes, code paths that
# the furnace instances of the same estimators already cover (80% of the sanitized suite's time,
# 545 of 615 s, which would put CI near its limit); the image checksums, recorded from the
# Release (g++) build, which a clang build need not match to the last bit (since 2026-11-28 one
# of the 15 images differs); and the VDB fuzz corpus, whose damaged files make OpenVDB itself
# request allocations that AddressSanitizer aborts on (a Release build gets std::bad_alloc and
# the one-line error the test checks).
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/phase.sh
phase "sanitized configure" env CXX=clang++ cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNIMBUS_SANITIZE=ON \
  -DNIMBUS_BUILD_FUZZER=ON -DNIMBUS_BUILD_BENCH=OFF >/dev/null
phase "sanitized build" cmake --build build-sanitize -j"$(nproc)"
repeats='Modes/(MediaRender|SpectralRender)\.(Chandrasekhar|EmittingField|SingleScattering)'
phase "sanitized tests" ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" \
  -E "^InstallAndEmbed$|^${repeats}|^Modes/SpectralRender\.EmissiveFurnace|^ImageChecksums$"
phase "fuzzing" bash tools/fuzz.sh --runs 200000
