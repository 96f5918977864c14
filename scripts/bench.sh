#!/usr/bin/env bash
# Builds and runs every benchmark program, writing Google Benchmark JSON to out/bench/<name>.json.
# Results are recorded by hand in docs/benchmarks.md with the command that produced them.
# Usage: scripts/bench.sh [name_filter]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
bin="${PLANELOC_BUILD_DIR:-$root/build}/bin"
mkdir -p "$root/out/bench"
for program in "$bin"/*_bench; do
  name="$(basename "$program")"
  if [ $# -gt 0 ] && [[ "$name" != *"$1"* ]]; then continue; fi
  echo "=== $name"
  "$program" --benchmark_format=console --benchmark_out="$root/out/bench/$name.json" \
    --benchmark_out_format=json
done
