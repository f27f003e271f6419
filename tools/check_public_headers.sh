#!/usr/bin/env bash
# Checks that the installed headers (cmake/public_headers.cmake) are exactly nimbus.h and what it
# includes, directly or through others (docs/api.md): a public header that includes a private
# one would not compile once installed, and a listed header that nimbus.h does not need is
# public by mistake. Prints each difference and exits 1 if there is any.
set -euo pipefail
root="$(cd "${1:-$(dirname "$0")/..}" && pwd)"
declare -A seen=()
visit() {
  local h="$1"
  [ -n "${seen[$h]+x}" ] && return
  seen[$h]=1
  [ -f "$root/src/nimbus/$h" ] || { echo "check_public_headers: $h is included but missing"; exit 1; }
  local next
  for next in $(grep -oE '#include "nimbus/[^"]+"' "$root/src/nimbus/$h" |
                sed -E 's|#include "nimbus/(.*)"|\1|'); do
    visit "$next"
  done
}
visit nimbus.h
needed=$(printf '%s\n' "${!seen[@]}" | sort)
listed=$(sed -n '/^set(NIMBUS_PUBLIC_HEADERS/,/^)/p' "$root/cmake/public_headers.cmake" |
         grep -E '^\s+[a-z0-9_/]+\.h$' | tr -d ' ' | sort)
bad=0
while read -r h; do
  echo "check_public_headers: nimbus.h needs $h, which cmake/public_headers.cmake does not list"
  bad=1
done < <(comm -23 <(echo "$needed") <(echo "$listed"))
while read -r h; do
  echo "check_public_headers: cmake/public_headers.cmake lists $h, which nimbus.h does not include"
  bad=1
done < <(comm -13 <(echo "$needed") <(echo "$listed"))
[ $bad = 0 ] && echo "check_public_headers: $(echo "$listed" | wc -l) public headers, as nimbus.h needs"
exit $bad
