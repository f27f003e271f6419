#!/usr/bin/env bash
# Sets up (Debian packages), builds nimbus in Release and runs the whole test suite, then runs it
# again under sanitizers and fuzzes the scene loader briefly (tools/sanitize.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/phase.sh
phase "set-up" bash tools/setup.sh
phase "Release configure" cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
phase "Release build" cmake --build build -j"$(nproc)"
phase "Release tests" ctest --test-dir build --output-on-failure -j"$(nproc)"
# The sanitized pass (clang, ASan, UBSan) and a fixed fuzzing run: tools/sanitize.sh.
bash tools/sanitize.sh
