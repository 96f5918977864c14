#!/usr/bin/env bash
# Threaded (default) vs --deterministic local BA on prepared simulator runs (issue 10 item 6).
# Each DIR holds sim/sequences/00, sim/poses/00.txt and planes.json (e.g. from bench_wrong_map.sh
# or `planeloc sim` + `map build` + `map planes`). Per DIR and mode, `planeloc run --planes` from
# the GT first pose (default --init-sigma) and `planeloc eval --align none`; threaded runs are
# repeated REPEATS times (they are not bit-identical). Prints one line per run:
#   tag dir mode repeat ate_m keyframes ba_counts_json
# Usage: scripts/bench_threaded_ba.sh --bin PLANELOC --out OUT --tag TAG [--repeats N]
#        [--no-planes | --exact-start] DIR...
# --exact-start: --init-sigma "0 0 0" (planes from frame 0, no registration worker), which
# isolates the local BA from the map lock's timing.
set -euo pipefail
bin=build/bin/planeloc out=/tmp/bench_threaded_ba tag=run repeats=2 planes=1 exact=0
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --tag) tag="$2"; shift 2 ;;
    --repeats) repeats="$2"; shift 2 ;;
    --no-planes) planes=0; shift ;;
    --exact-start) exact=1; shift ;;
    *) break ;;
  esac
done
for dir in "$@"; do
  name="$(basename "$dir")"
  for mode in deterministic threaded; do
    n=1
    [ "$mode" = threaded ] && n="$repeats"
    for ((r = 0; r < n; r++)); do
      o="$out/$tag/$name-$mode-$r"
      mkdir -p "$(dirname "$o")"
      flags=()
      [ "$mode" = deterministic ] && flags+=(--deterministic)
      if [ "$planes" = 1 ]; then flags+=(--planes "$dir/planes.json"); else flags+=(--no-planes); fi
      [ "$exact" = 1 ] && flags+=(--init-sigma "0 0 0")
      "$bin" run --sequence "$dir/sim/sequences/00" --init-pose-from "$dir/sim/poses/00.txt" \
        "${flags[@]}" --out "$o.txt" --stats "$o.jsonl" > "$o.log" 2>&1
      ate=$("$bin" eval --gt "$dir/sim/poses/00.txt" --est "$o.txt" --align none 2>&1 |
        awk '/APE trans/ {print $5}')
      kf=$(grep -c '"keyframe":true' "$o.jsonl" || true)
      counts=$(cat "$o.jsonl.summary.json" 2>/dev/null | grep -oE '"local_ba":\{[^}]*\}' || echo "-")
      echo "$tag $name $mode $r $ate $kf $counts"
    done
  done
done
