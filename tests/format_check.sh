#!/usr/bin/env bash
# Fails when a tracked C++ file differs from clang-format (Google style, 100 columns).
# Usage: format_check.sh SOURCE_DIR
set -u
cd "$1" || exit 1
if ! command -v clang-format >/dev/null 2>&1; then
  echo "clang-format not installed (scripts/setup.sh installs it)"
  exit 1
fi
files=$(git ls-files '*.cc' '*.h' 2>/dev/null || find src apps bench -name '*.cc' -o -name '*.h')
bad=0
for file in $files; do
  if ! clang-format --dry-run -Werror "$file" >/dev/null 2>&1; then
    echo "not clang-formatted: $file (fix: clang-format -i $file)"
    bad=$((bad + 1))
  fi
done
echo "format: $(($(wc -w <<<"$files") - bad)) passed, $bad failed"
[ "$bad" -eq 0 ]
