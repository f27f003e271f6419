#!/usr/bin/env bash
# Checks that includes between the modules of src/nimbus point one way (docs/architecture.md,
# "Dependency order"): a module includes itself and modules of a lower rank only (math and os,
# frep and spectral, and media and mesh, share a rank and stay independent). Prints each include that runs upward or
# sideways, and exits 1 if there is any.
set -euo pipefail
src="${1:-$(dirname "$0")/../src/nimbus}"
declare -A rank=([math]=0 [os]=0 [frep]=1 [spectral]=1 [media]=2 [mesh]=2 [tracking]=3 [render]=4 [scene]=5
                 [io]=6 [job]=7 [experiments]=7 [view]=8)
bad=0
for module in "${!rank[@]}"; do
  [ -d "$src/$module" ] || { echo "check_layers: no module $module in $src" >&2; exit 1; }
  while IFS=: read -r file line target; do
    if [ -z "${rank[$target]+x}" ]; then
      echo "$file:$line: includes unknown module $target"
      bad=1
    elif [ "$target" != "$module" ] && [ "${rank[$target]}" -ge "${rank[$module]}" ]; then
      echo "$file:$line: $module includes $target, which is not below it"
      bad=1
    fi
  done < <(grep -rnoE '#include "nimbus/[a-z_]+/' "$src/$module" |
           sed -E 's|#include "nimbus/([a-z_]+)/|\1|')
done
exit $bad
