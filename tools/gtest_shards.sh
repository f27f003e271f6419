#!/usr/bin/env bash
# Runs a GoogleTest binary's tests in SHARDS processes (GoogleTest's own sharding), JOBS at a
# time: one process start per shard instead of one per test, which under the sanitizers is 0.2 s
# of CPU each (docs/testing.md, "How CI's time is spent"). Prints one line per shard, the whole
# output of every shard that failed, and a last line "N passed, M failed".
#   tools/gtest_shards.sh BINARY JOBS SHARDS [GTEST_FILTER]
set -euo pipefail
binary=$1 jobs=$2 shards=$3 filter=${4:-*}
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
run_shard() {
  local i=$1 start=$SECONDS code=0
  # A shard that hangs is stopped after 30 minutes, as ctest would stop a test.
  GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i timeout 1800 "$binary" --gtest_filter="$filter" \
    --gtest_brief=1 >"$logs/$i.log" 2>&1 || code=$?
  echo "$code" >"$logs/$i.code"
  echo "shard $((i + 1))/$shards: exit $code in $((SECONDS - start)) s"
}
export -f run_shard
export binary shards filter logs
seq 0 $((shards - 1)) | xargs -P "$jobs" -I{} bash -c 'run_shard {}'
passed=0 failed=0
for ((i = 0; i < shards; ++i)); do
  n=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) tests\?\.$/\1/p' "$logs/$i.log")
  passed=$((passed + ${n:-0}))
  if [ "$(cat "$logs/$i.code")" != 0 ]; then
    echo "--- shard $((i + 1))/$shards failed:"
    cat "$logs/$i.log"
    f=$(grep -c '^\[  FAILED  \] .*)$' "$logs/$i.log" || true)
    failed=$((failed + (f > 0 ? f : 1)))
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
