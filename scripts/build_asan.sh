#!/usr/bin/env bash
# Configures and builds the sanitizer tree: clang, ASan + UBSan, the libFuzzer targets, no
# benchmarks, into build-asan/ (PLANELOC_ASAN_BUILD_DIR). Prints the build folder on stdout (the
# build's own output goes to stderr). Used by `scripts/test.sh --sanitize` and scripts/fuzz.sh.
# Usage: scripts/build_asan.sh [extra cmake args]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${PLANELOC_ASAN_BUILD_DIR:-$root/build-asan}"
jobs="${PLANELOC_JOBS:-$(nproc)}"
if ! command -v clang++ >/dev/null 2>&1; then
  echo "build_asan.sh: clang++ not installed (scripts/setup.sh installs it)" >&2
  exit 2
fi
# -O1: the sanitizers' recommended level (usable stack traces); NDEBUG as in the shipped Release
# build, so that the suite checks the code users run. -gline-tables-only: file:line in reports.
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
  "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -gline-tables-only -DNDEBUG" \
  -DPLANELOC_SANITIZE=ON -DPLANELOC_BUILD_FUZZ=ON -DPLANELOC_BUILD_BENCH=OFF "$@" >&2
cmake --build "$build_dir" -j "$jobs" >&2
echo "$build_dir"
