#!/usr/bin/env bash
# The fuzzers (docs/testing.md, "Fuzzing"): builds the libFuzzer targets in build-sanitize/
# (clang, ASan, UBSan; tools/sanitize.sh shares that build; NIMBUS_FUZZ_BUILD=DIR builds in DIR
# instead) and fuzzes from a committed corpus: the scene target from fuzz/corpus with the
# scene-format dictionary fuzz/scene.dict, with --vdb the VDB reader's target from
# fuzz/vdb_corpus, or with --files the target of checkpoints, film files, .npy files and the
# viewer's camera body from fuzz/files_corpus.
#   tools/fuzz.sh [--vdb|--files] [SECONDS] [JOBS]   fuzz for SECONDS (default 60) with JOBS
#                                            processes (default 1); new inputs go to
#                                            BUILD/fuzz-corpus (or BUILD/vdb-fuzz-corpus,
#                                            BUILD/files-fuzz-corpus)
#   tools/fuzz.sh [--vdb|--files] --runs N [JOBS]   N inputs in all from fixed seeds (JOBS processes,
#                                            default 1, process k with seed k and N / JOBS
#                                            inputs), new inputs discarded: the deterministic
#                                            check that tools/sanitize.sh runs
# A finding is written to BUILD/fuzz-findings/ and fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${NIMBUS_FUZZ_BUILD:-build-sanitize}
target=nimbus_fuzz
corpus=fuzz/corpus
kept=fuzz-corpus
# -max_len: the largest hand-written shipped scene is 7.3 kB (scenes/lanterns.json, written by
# tools/make_lanterns.py, is 217 kB: libFuzzer reads it cut at max_len, as malformed JSON).
options=(-dict=fuzz/scene.dict -max_len=8192)
if [ "${1:-}" = "--vdb" ]; then
  shift
  target=nimbus_vdb_fuzz
  corpus=fuzz/vdb_corpus
  kept=vdb-fuzz-corpus
  # The corpus's files are at most 16 kB. No leak reports: OpenVDB leaks the nodes of a tree
  # whose reading threw (docs/testing.md).
  options=(-max_len=16384 -detect_leaks=0)
elif [ "${1:-}" = "--files" ]; then
  shift
  target=nimbus_files_fuzz
  corpus=fuzz/files_corpus
  kept=files-fuzz-corpus
  # The corpus's files are at most 8 kB.
  options=(-max_len=8192)
fi
bash tools/configure.sh sanitize "$build"
cmake --build "$build" -j"$(nproc)" --target "$target"
mkdir -p "$build/fuzz-findings"
# -timeout: an input that takes 20 s is a hang worth reporting; -rss_limit_mb: the same for
# memory.
options+=(-timeout=20 -rss_limit_mb=2048 -artifact_prefix="$build/fuzz-findings/"
  -print_final_stats=1)
if [ "${1:-}" = "--runs" ]; then
  jobs=${3:-1}
  scratch=$(mktemp -d)
  trap 'rm -rf "$scratch"' EXIT
  pids=()
  for ((k = 1; k <= jobs; ++k)); do
    mkdir "$scratch/$k"
    # One log per process, shown in order once all are done.
    "./$build/$target" "${options[@]}" -seed="$k" -runs="$(($2 / jobs))" "$scratch/$k" \
      "$corpus" >"$scratch/$k.log" 2>&1 &
    pids+=($!)
  done
  failed=0
  for ((k = 1; k <= jobs; ++k)); do
    wait "${pids[k - 1]}" || failed=1
    cat "$scratch/$k.log"
  done
  exit "$failed"
fi
seconds=${1:-60}
jobs=${2:-1}
parallel=()
if [ "$jobs" -gt 1 ]; then parallel=(-jobs="$jobs" -workers="$jobs"); fi
mkdir -p "$build/$kept"
"./$build/$target" "${options[@]}" -max_total_time="$seconds" "${parallel[@]}" \
  "$build/$kept" "$corpus"
