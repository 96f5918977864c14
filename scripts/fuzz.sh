#!/usr/bin/env bash
# Runs every libFuzzer target (src/planeloc/**/*_fuzz.cc) for SECONDS each, two at a time
# (PLANELOC_JOBS), in the sanitizer tree build-asan/ (built by scripts/build_asan.sh: ASan + UBSan).
# Seeds: tests/fuzz_corpus/<target>/; the growing corpus stays in build-asan/fuzz/<target>/corpus
# (not in git), crashing inputs in build-asan/fuzz/<target>/. Prints one line a target (execs,
# exec/s, corpus) and exits 1 when any target found a crash, leak, timeout or out-of-memory;
# each finding's report and input (base64) are printed after the table.
#
# Usage: scripts/fuzz.sh SECONDS [TARGET...]   (targets: kitti_calib trajectory pcd_reader
#        ply_reader xyz plane_map settings_reader; default all)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
all_targets=(kitti_calib trajectory pcd_reader ply_reader xyz plane_map settings_reader)

usage() {
  sed -n '2,/^set /{/^#/p}' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
[ $# -ge 1 ] || usage
seconds="$1"
shift
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || usage
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for target in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $target "* ]] || { echo "fuzz.sh: unknown target '$target'" >&2; usage; }
done

# PLANELOC_FUZZ_NO_BUILD=1: use build-asan/ as it is (e.g. while another build of it runs).
if [ "${PLANELOC_FUZZ_NO_BUILD:-0}" = 1 ]; then
  build_dir="${PLANELOC_ASAN_BUILD_DIR:-$root/build-asan}"
else
  build_dir="$("$root/scripts/build_asan.sh")"
fi
# shellcheck source=scripts/sanitizer_env.sh
source "$root/scripts/sanitizer_env.sh"
jobs="${PLANELOC_JOBS:-$(nproc)}"

run_target() {
  local target="$1" work="$build_dir/fuzz/$1"
  mkdir -p "$work/corpus"
  # -max_len 4096: every seed is below 1.5 kB and the readers' defects so far needed a few
  # hundred bytes; longer inputs only slow the search. -timeout 10 s: the largest valid input
  # reads in milliseconds, so 10 s is a hang. -rss_limit_mb 2048 (libFuzzer's default, stated
  # here): a header claiming 10^12 points must be an error, not an allocation.
  "$build_dir/bin/planeloc_${target}_fuzz" -max_total_time="$seconds" -max_len=4096 -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/" \
    "$work/corpus" "$root/tests/fuzz_corpus/${target}_fuzz" >"$work/log" 2>&1
}

# A sanitizer report, a libFuzzer error (crash, leak, timeout, out-of-memory) or a deadly signal.
finding_pattern='^==[0-9]+== ?ERROR|^SUMMARY: |runtime error:|deadly signal'

declare -A pids=()
status=0
for target in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run_target "$target" &
  pids[$target]=$!
done
for target in "${targets[@]}"; do
  if ! wait "${pids[$target]}"; then status=1; fi
done

printf '%-16s %12s %8s %8s %8s  %s\n' target execs exec/s corpus rss_mb result
for target in "${targets[@]}"; do
  work="$build_dir/fuzz/$target"
  fuzz_stat() { sed -n "s/^stat::$1: *//p" "$work/log" | tail -1; }
  result=clean
  if grep -qE "$finding_pattern" "$work/log"; then
    result="FINDING (see $work/log)"
    status=1
  fi
  printf '%-16s %12s %8s %8s %8s  %s\n' "$target" "$(fuzz_stat number_of_executed_units)" \
    "$(fuzz_stat average_exec_per_sec)" \
    "$(grep -oE 'corp: [0-9]+' "$work/log" | tail -1 | cut -d' ' -f2)" \
    "$(fuzz_stat peak_rss_mb)" "$result"
done

# A CI machine's build tree is gone after the run: print each finding's report and its input
# (base64; inputs are at most 4 kB) so that the CI record alone lets anyone replay it:
# `base64 -d > input; build-asan/bin/planeloc_<target>_fuzz input`.
for target in "${targets[@]}"; do
  work="$build_dir/fuzz/$target"
  grep -qE "$finding_pattern" "$work/log" || continue
  echo "== finding in $target: the report (first 60 lines from the first error)"
  awk -v pattern="$finding_pattern" '$0 ~ pattern { found = 1 } found' "$work/log" | head -60 || true
  for input in "$work"/crash-* "$work"/leak-* "$work"/timeout-* "$work"/oom-* "$work"/slow-unit-*; do
    [ -f "$input" ] || continue
    echo "== $target input $(basename "$input") ($(wc -c <"$input") bytes), base64:"
    base64 -w 0 "$input"
    echo
  done
done
exit "$status"
