# Sourced by tools/test.sh and tools/sanitize.sh: `phase NAME COMMAND...` runs COMMAND and prints
# its wall time, so that every CI log carries the phase table of docs/testing.md.
phase() {
  local name=$1 start=$SECONDS
  shift
  "$@"
  echo "phase: ${name}: $((SECONDS - start)) s (load $(cut -d' ' -f1-3 /proc/loadavg))" >&2
}
