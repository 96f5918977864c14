#!/usr/bin/env bash
# Set-up, build and run every test with ctest. Tests that need ../shared/data skip when it is
# missing, unless PLANELOC_REQUIRE_SHARED_DATA=1 (CI), where they fail.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
build_dir="${PLANELOC_BUILD_DIR:-$root/build}"
cd "$build_dir"
ctest --output-on-failure -j "${PLANELOC_JOBS:-$(nproc)}" --timeout 900 "$@"
