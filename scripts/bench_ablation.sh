#!/usr/bin/env bash
# Issue 10 ablation: the plane term's weight, the window at turns, the association gate and the
# trajectory consensus, each changed alone from the defaults, on the clean plane map and on the map
# with 20 % of its planes moved by 0.2 m (scripts/bench_wrong_map.sh with --config per variant).
# Exact start, --deterministic, ATE RMSE without alignment. Prints one block per variant.
#
# Usage: scripts/bench_ablation.sh [--preset small] [--seeds "3 11 21"] [--out DIR]
#        [--kinds "vo clean move0.2"] [--variants "default lambda1 ..."]
# Variants:
#   default        today's settings (λ = LocalBA.lambda 0.5, χ² gate, adaptive window)
#   lambda1/0.8/0.2 LocalBA.lambda 1 (plane term off: reprojection only), 0.8, 0.2
#   fixedwindow    LocalBA.windowKeyframesTurn = LocalBA.windowKeyframes (no growth at turns)
#   oldgate        the fixed 15 cm band of the first release: no χ² gate (Planes.gateChi2 1e9),
#                  so only Planes.maxDistance decides
#   noconsensus    Planes.trajectoryConsensus 0 (facades that agree on the trajectory's offset
#                  no longer move the map back)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset=small
seeds="3 11 21"
out=/tmp/planeloc-bench-wrong-map
kinds="clean move0.2"
variants="default lambda1 lambda0.8 lambda0.2 fixedwindow oldgate"
while [ $# -gt 0 ]; do
  case "$1" in
    --preset) preset="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --kinds) kinds="$2"; shift 2 ;;
    --variants) variants="$2"; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "bench_ablation.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
mkdir -p "$out/ablation"
for variant in $variants; do
  cfg="$out/ablation/$variant.yaml"
  case "$variant" in
    default) printf '%%YAML:1.0\n' >"$cfg" ;;
    lambda*) printf '%%YAML:1.0\nLocalBA.lambda: %s\n' "${variant#lambda}" >"$cfg" ;;
    fixedwindow) printf '%%YAML:1.0\nLocalBA.windowKeyframesTurn: 10\n' >"$cfg" ;;
    oldgate) printf '%%YAML:1.0\nPlanes.gateChi2: 1e9\n' >"$cfg" ;;
    noconsensus) printf '%%YAML:1.0\nPlanes.trajectoryConsensus: 0\n' >"$cfg" ;;
    *) echo "bench_ablation.sh: unknown variant '$variant' (see --help)" >&2; exit 2 ;;
  esac
  echo "## $variant"
  "$root/scripts/bench_wrong_map.sh" --preset "$preset" --seeds "$seeds" --out "$out" \
    --config "$cfg" --tag "abl-$variant" --kinds "$kinds"
done
