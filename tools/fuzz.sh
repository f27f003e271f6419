#!/usr/bin/env bash
# The fuzzer (docs/testing.md, "Fuzzing"): builds the libFuzzer scene target in build-sanitize/
# (clang, ASan, UBSan; tools/sanitize.sh shares that build) and fuzzes from the committed corpus
# fuzz/corpus with the scene-format dictionary fuzz/scene.dict.
#   tools/fuzz.sh [SECONDS] [JOBS]   fuzz for SECONDS (default 60) with JOBS processes (default
#                                    1); new inputs go to build-sanitize/fuzz-corpus
#   tools/fuzz.sh --runs N           N inputs from a fixed seed, new inputs discarded: the
#                                    deterministic check that tools/sanitize.sh runs
# A finding is written to build-sanitize/fuzz-findings/ and fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
CXX=clang++ cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNIMBUS_SANITIZE=ON \
  -DNIMBUS_BUILD_FUZZER=ON -DNIMBUS_BUILD_BENCH=OFF >/dev/null
cmake --build build-sanitize -j"$(nproc)" --target nimbus_fuzz
mkdir -p build-sanitize/fuzz-findings
# -timeout: a tiny render that takes 20 s is a hang worth reporting; -rss_limit_mb: the same for
# memory. -max_len: the largest shipped scene is 7.3 kB.
options=(-dict=fuzz/scene.dict -timeout=20 -rss_limit_mb=2048 -max_len=8192
  -artifact_prefix=build-sanitize/fuzz-findings/ -print_final_stats=1)
if [ "${1:-}" = "--runs" ]; then
  scratch=$(mktemp -d)
  trap 'rm -rf "$scratch"' EXIT
  ./build-sanitize/nimbus_fuzz "${options[@]}" -seed=1 -runs="$2" "$scratch" fuzz/corpus
  exit
fi
seconds=${1:-60}
jobs=${2:-1}
parallel=()
if [ "$jobs" -gt 1 ]; then parallel=(-jobs="$jobs" -workers="$jobs"); fi
mkdir -p build-sanitize/fuzz-corpus
./build-sanitize/nimbus_fuzz "${options[@]}" -max_total_time="$seconds" "${parallel[@]}" \
  build-sanitize/fuzz-corpus fuzz/corpus
