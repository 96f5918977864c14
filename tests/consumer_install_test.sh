#!/usr/bin/env bash
# Issue 14: planeloc as a CMake package. Installs the build tree into a temporary prefix, builds
# examples/consumer against it with find_package(planeloc), runs it on 8 frames of the tiny
# preset (the installed `planeloc sim`), and checks that its poses are the ones `planeloc run
# --deterministic` writes for the same frames (byte for byte: both drive the same Tracker).
# Usage: consumer_install_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build="$1"
source_dir="$2"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/planeloc-consumer.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL $1"; [ -f "$2" ] && tail -30 "$2"; exit 1; }
step() {  # step NAME COMMAND...
  local name="$1"; shift
  "$@" >"$tmp/$name.log" 2>&1 || fail "$name" "$tmp/$name.log"
  echo "ok $name"
}
prefix="$tmp/prefix"
step install cmake --install "$build" --prefix "$prefix"
for f in lib/cmake/planeloc/planelocConfig.cmake include/planeloc/localizer/localizer.h \
         include/planeloc/pipeline/tracker.h lib/libplaneloc_tracking.a bin/planeloc; do
  [ -e "$prefix/$f" ] || fail "installed $f" /dev/null
done
[ -z "$(find "$prefix/include" -name '*_test.h' -o -name 'test_*.h')" ] || \
  fail "no test headers installed" /dev/null
echo "ok installed headers, libraries, config and CLI"
step sim "$prefix/bin/planeloc" sim --out "$tmp/sim" --preset tiny --frames 8
step configure cmake -S "$source_dir/examples/consumer" -B "$tmp/consumer" \
  -DCMAKE_PREFIX_PATH="$prefix"
step build cmake --build "$tmp/consumer" -j2
seq="$tmp/sim/sequences/00"
planes="$tmp/sim/world/planes_gt.json"
step consumer "$tmp/consumer/localize_kitti" "$seq" "$planes" 8 "$tmp/consumer.txt"
grep -q "8 of 8 frames localized" "$tmp/consumer.log" || fail "8 of 8 localized" "$tmp/consumer.log"
step run "$prefix/bin/planeloc" run --sequence "$seq" --planes "$planes" --init-sigma "0 0 0" \
  --deterministic --frames 8 --out "$tmp/run.txt"
cmp "$tmp/consumer.txt" "$tmp/run.txt" || fail "consumer poses == planeloc run poses" /dev/null
echo "ok consumer poses == planeloc run --deterministic poses (8 frames)"
echo "consumer: 6 passed, 0 failed"
