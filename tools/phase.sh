# Sourced by tools/test.sh and tools/sanitize.sh: `phase NAME COMMAND...` runs COMMAND and prints
# its wall time, so that every CI log carries the phase table of docs/testing.md.
phase() {
  local name=$1 start=$SECONDS
  shift
  "$@"
  echo "phase: ${name}: $((SECONDS - start)) s (load $(cut -d' ' -f1-3 /proc/loadavg))" >&2
}

# `suites BUILD_DIR GTEST_FILTER [CTEST ARGS...]`: the scripted tests under ctest, one at a time
# in the background, beside the GoogleTest binary in 16 shards on every core
# (tools/gtest_shards.sh): alone, ctest's longest test (Python, about 60 s) kept one core busy
# while the other idled. ctest's output follows the shards' lines; either failing fails.
suites() {
  local dir=$1 filter=$2 log code=0
  shift 2
  log=$(mktemp)
  ctest --test-dir "$dir" --output-on-failure -LE gtest "$@" >"$log" 2>&1 &
  local ctest_pid=$!
  bash tools/gtest_shards.sh "$dir/nimbus_tests" "$(nproc)" 16 "$filter" || code=1
  wait "$ctest_pid" || code=1
  cat "$log"
  rm -f "$log"
  return "$code"
}
