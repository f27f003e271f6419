#!/usr/bin/env bash
# Sets up (Debian packages), builds nimbus in Release and runs the whole test suite, then runs it
# again under sanitizers and fuzzes the scene loader briefly (tools/sanitize.sh). Each phase
# prints its wall time. `--all` also runs, under the sanitizers, the tests that CI runs in the
# Release pass only (docs/testing.md, "Tiers").
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/phase.sh
phase "set-up" bash tools/setup.sh
phase "Release configure" bash tools/configure.sh release
phase "Release build" cmake --build build -j"$(nproc)"
# The scripted tests under ctest beside the GoogleTest binary in shards (tools/phase.sh):
# `ctest --test-dir build` runs each test alone.
release_tests() { suites build '*'; }
phase "Release tests" release_tests
bash tools/sanitize.sh "$@"
