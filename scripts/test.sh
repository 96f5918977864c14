#!/usr/bin/env bash
# Set-up, build and run every test with ctest. Tests that need ../shared/data skip when it is
# missing, unless PLANELOC_REQUIRE_SHARED_DATA=1 (CI), where they fail.
#
# Usage: scripts/test.sh [--sanitize [--skip-slow]] [ctest args...]
#   --sanitize   build with clang, AddressSanitizer and UndefinedBehaviorSanitizer (and the fuzz
#                targets) into build-asan/ (PLANELOC_ASAN_BUILD_DIR) and run the whole suite there;
#                any sanitizer report fails its test (docs/reliability.md, "Sanitizers").
#   --skip-slow  with --sanitize: leave out the tests labelled `slow` (the long synthetic-sequence
#                suites) and `no_sanitize` (install.consumer, which cannot work under ASan, and
#                the end-to-end CLI tests that re-run code the sanitized suites and fuzz targets
#                cover; tests/CMakeLists.txt says why for each), as CI does to stay in its time
#                budget. The plain run covers all of them.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

sanitize=0
exclude='^format$'
if [ "${1:-}" = "--sanitize" ]; then
  sanitize=1
  shift
  if [ "${1:-}" = "--skip-slow" ]; then
    exclude='^(format|slow|no_sanitize)$'
    shift
  fi
elif [ "${1:-}" = "-h" ] || [ "${1:-}" = "--help" ]; then
  sed -n '2,/^set /{/^#/p}' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 0
fi

"$root/scripts/setup.sh"
if [ "$sanitize" -eq 0 ]; then
  "$root/scripts/build.sh"
  build_dir="${PLANELOC_BUILD_DIR:-$root/build}"
  cd "$build_dir"
  ctest --output-on-failure -j "${PLANELOC_JOBS:-$(nproc)}" --timeout 900 "$@"
  exit 0
fi

build_dir="$("$root/scripts/build_asan.sh")"
# shellcheck source=scripts/sanitizer_env.sh
source "$root/scripts/sanitizer_env.sh"
cd "$build_dir"
# Every test but format.clang_format, which runs clang-format over the sources and none of our
# code (the plain run above checks it), and with --skip-slow the `slow` and `no_sanitize` ones
# (ctest -LE matches each label of a test: one excluded label leaves the test out). --timeout only
# covers tests without their own TIMEOUT.
if ctest --output-on-failure -j "${PLANELOC_JOBS:-$(nproc)}" --timeout 1800 -LE "$exclude" "$@"; then
  exit 0
fi
# LeakSanitizer's tracer can itself crash at process exit (google/sanitizers#1353) after every test
# of a binary passed. A test whose only fault is that crash runs once more; any other fault (a
# failed case, a sanitizer report, a leak, a timeout) fails the run as it is.
if ! tracer_only="$(python3 "$root/scripts/lsan_tracer_crashes.py" "$build_dir")"; then
  exit 1
fi
for test in $tracer_only; do
  echo "test.sh: '$test' failed only by LeakSanitizer's tracer crash; running it once more" >&2
  ctest --output-on-failure --timeout 1800 -R "^${test//./\\.}\$"
done
