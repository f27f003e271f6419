#!/usr/bin/env bash
# Checks that the tables of render settings in docs/scene-format.md are what the settings'
# declarations say (src/nimbus/render/settings.cpp): each block between
# "<!-- settings: SECTION ..." and "<!-- end of settings -->" must equal
# `nimbus settings --markdown SECTION`. Prints the difference and exits 1 otherwise; regenerate
# a block by pasting that command's output in its place.
# Usage: tools/check_settings_docs.sh NIMBUS DOCS
set -euo pipefail
nimbus=$1
docs=$2
bad=0
for section in film integrator spectrum; do
  documented=$(sed -n "/^<!-- settings: $section /,/^<!-- end of settings -->/p" "$docs" |
               sed '1d;$d')
  if [ -z "$documented" ]; then
    echo "check_settings_docs: $docs has no block <!-- settings: $section ... -->"
    bad=1
  elif ! diff <(echo "$documented") <("$nimbus" settings --markdown "$section") \
         > /tmp/settings_diff.$$; then
    echo "check_settings_docs: the $section table of $docs differs from the declarations" \
         "(< docs, > nimbus settings --markdown $section):"
    cat /tmp/settings_diff.$$
    bad=1
  fi
  rm -f /tmp/settings_diff.$$
done
[ $bad = 0 ] && echo "check_settings_docs: the film, integrator and spectrum tables are current"
exit $bad
