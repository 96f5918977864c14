#!/usr/bin/env bash
# Issue 10 item 1 ablation: ATE (no alignment) of `planeloc run --deterministic` with the LSD
# crease gate off (Planes.creaseGate: 0, the default) and on, with the clean plane map and wrong
# ones (scripts/corrupt_planes.py), on the data layout of scripts/bench_wrong_map.sh (run that
# first, or let this script build it: it calls bench_wrong_map.sh's steps for missing maps).
# Prints per seed and map: ATE off, ATE on, and from the gate-on run's stats: keyframes checked,
# mean visible / confirmed creases per checked keyframe, median of the per-keyframe median edge
# distances (px), associations refused by the gate (sum over keyframes; outside the region,
# across a crease).
#
# Usage: scripts/bench_crease_gate.sh [--preset tiny|small] [--seeds "3 11 21"] [--out DIR]
#        [--maps "clean move0.2"] [--init-sigma "0 0 0"] [--variant both] [--side-tolerance PX]
# The start is exact by default (--init-sigma "0 0 0": planes active from frame 0, as in the
# wrong-map table of docs/experiments.md); "2 0.5 5" adds the map lock. --variant both|region|side:
# the gate's tests used in the "on" runs (both by default; region: Planes.creaseGateSide 0;
# side: Planes.creaseGateRegion 0); --side-tolerance PX sets Planes.creaseSideTolerancePx.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
planeloc="${PLANELOC_BIN:-${PLANELOC_BUILD_DIR:-$root/build}/bin/planeloc}"
preset=small
seeds="3 11 21"
out=/tmp/planeloc-bench-wrong-map
maps="clean move0.2"
init_sigma="0 0 0"
variant=both
side_tol=""
while [ $# -gt 0 ]; do
  case "$1" in
    --preset) preset="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --maps) maps="$2"; shift 2 ;;
    --init-sigma) init_sigma="$2"; shift 2 ;;
    --variant) variant="$2"; shift 2 ;;
    --side-tolerance) side_tol="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "bench_crease_gate.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
printf '%%YAML:1.0\nPlanes.creaseGate: 0\n' >"$out/gate_off.yaml"
case "$variant" in
  both) printf '%%YAML:1.0\nPlanes.creaseGate: 1\n' >"$out/gate_on.yaml" ;;
  region) printf '%%YAML:1.0\nPlanes.creaseGate: 1\nPlanes.creaseGateSide: 0\n' >"$out/gate_on.yaml" ;;
  side) printf '%%YAML:1.0\nPlanes.creaseGate: 1\nPlanes.creaseGateRegion: 0\n' >"$out/gate_on.yaml" ;;
  *) echo "bench_crease_gate.sh: --variant must be both, region or side" >&2; exit 2 ;;
esac
on=on
[ "$variant" = both ] || on="on_$variant"
if [ -n "$side_tol" ]; then
  echo "Planes.creaseSideTolerancePx: $side_tol" >>"$out/gate_on.yaml"
  on="${on}_tol$side_tol"
fi
ate() {
  "$planeloc" eval --gt "$1" --est "$2" --align none --json "$2.ate.json" >/dev/null
  python3 -c 'import json,sys; print("%.4f" % json.load(open(sys.argv[1]))["ape"]["rmse"])' "$2.ate.json"
}
crease_stats() {  # keyframes, mean visible, mean confirmed, median edge px, refused
  python3 - "$1" <<'EOF'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
checks = [r["crease_check"] for r in rows if "crease_check" in r]
if not checks:
    print("0 - - - - -"); sys.exit()
edges = [c["median_edge_px"] for c in checks if "median_edge_px" in c]
print(len(checks), "%.1f" % statistics.mean(c["visible_creases"] for c in checks),
      "%.1f" % statistics.mean(c["confirmed_creases"] for c in checks),
      "%.2f" % statistics.median(edges) if edges else "-",
      sum(c.get("gate_rejected_region", 0) for c in checks),
      sum(c.get("gate_rejected_side", 0) for c in checks))
EOF
}
echo "preset $preset, binary $planeloc"
echo "variant $variant"
echo "seed map ate_off ate_$on keyframes_checked visible confirmed median_edge_px refused_region refused_side"
for seed in $seeds; do
  d="$out/$preset-$seed"
  if [ ! -f "$d/planes.json" ]; then
    "$root/scripts/bench_wrong_map.sh" --preset "$preset" --seeds "$seed" --out "$out" >/dev/null
  fi
  for kind in $maps; do
    map="$d/planes.json"
    if [ "$kind" != clean ]; then
      map="$d/planes_$kind.json"
      if [ ! -f "$map" ]; then
        case "$kind" in
          move*) arg=(--move "${kind#move}") ;;
          rot*) arg=(--rotate-deg "${kind#rot}") ;;
        esac
        python3 "$root/scripts/corrupt_planes.py" "$d/planes.json" "$map" --seed "$seed" \
          --fraction 0.2 "${arg[@]}" 2>>"$d/log.txt"
      fi
    fi
    r="$d/crease"
    mkdir -p "$r"
    row="$seed $kind"
    for gate in off "$on"; do
      # The gate-off run is deterministic and does not depend on --variant: done once.
      if [ "$gate" = off ] && [ -s "$r/traj_${kind}_off.txt" ]; then
        row="$row $(ate "$d/sim/poses/00.txt" "$r/traj_${kind}_off.txt")"
        continue
      fi
      "$planeloc" run --sequence "$d/sim/sequences/00" --init-pose-from "$d/sim/poses/00.txt" \
        --planes "$map" --init-sigma "$init_sigma" --config "$out/gate_${gate%%_*}.yaml" \
        --deterministic \
        --out "$r/traj_${kind}_$gate.txt" --stats "$r/stats_${kind}_$gate.jsonl" \
        >"$r/run_${kind}_$gate.log" 2>&1
      row="$row $(ate "$d/sim/poses/00.txt" "$r/traj_${kind}_$gate.txt")"
    done
    echo "$row $(crease_stats "$r/stats_${kind}_$on.jsonl")"
  done
done
