#!/usr/bin/env bash
# Module layering (docs/architecture.md): a file of src/planeloc/<module>/ includes only its own
# module and the modules below it; a test file (*_test.cc, *_fuzz.cc, *for_test.h) may also
# include its module's test dependencies (src/planeloc/CMakeLists.txt, TEST_DEPS). CMake's link
# dependencies cannot catch a header-only include from above; this does.
#
# Usage: tests/module_layers_test.sh SOURCE_DIR
set -euo pipefail
src="${1:?usage: module_layers_test.sh SOURCE_DIR}/src/planeloc"

declare -A allowed=(
  [util]=""
  [geometry]="util"
  [io]="geometry util"
  [features]="geometry util"
  [optim]="geometry util"
  [eval]="io geometry util"
  [sim]="io geometry util"
  [map]="io optim geometry util"
  [tracking]="features optim io geometry util"
  [prior]="tracking features optim io geometry util"
  [pipeline]="prior tracking features optim io geometry util"
  [localizer]="pipeline prior tracking features optim io geometry util"
  [ros]="io geometry util"
  [view]="pipeline prior tracking features optim io eval geometry util"
)
declare -A test_allowed=(
  [map]="sim"
  [pipeline]="sim eval map"
  [localizer]="sim"
  [ros]="sim"
  [view]="sim map"
)

failures=0
checked=0
for dir in "$src"/*/; do
  module="$(basename "$dir")"
  if [[ ! -v "allowed[$module]" ]]; then
    echo "FAIL: module '$module' has no layer in tests/module_layers_test.sh; add it" >&2
    failures=$((failures + 1))
    continue
  fi
  while IFS= read -r -d '' file; do
    ok=" $module ${allowed[$module]} "
    case "$file" in
      *_test.cc | *_fuzz.cc | *for_test.h | */test_*.h) ok+="${test_allowed[$module]:-} " ;;
    esac
    while IFS=: read -r line target; do
      checked=$((checked + 1))
      if [[ "$ok" != *" $target "* ]]; then
        echo "FAIL: ${file#"$src"/}:$line includes planeloc/$target/, above or beside" \
          "'$module' (allowed: ${ok# })" >&2
        failures=$((failures + 1))
      fi
    done < <(grep -noE '^#include "planeloc/[a-z_]+/' "$file" | sed -E 's|^([0-9]+):.*planeloc/([a-z_]+)/$|\1:\2|')
  done < <(find "$dir" -type f \( -name '*.h' -o -name '*.cc' \) -print0)
done
[ "$checked" -gt 100 ] || { echo "FAIL: only $checked includes found under $src" >&2; exit 1; }
if [ "$failures" -gt 0 ]; then
  echo "$failures include(s) against the module layers" >&2
  exit 1
fi
echo "ok: $checked includes follow the module layers"
