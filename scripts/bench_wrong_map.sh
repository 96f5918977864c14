#!/usr/bin/env bash
# Issue 10 benchmark, "a map that can be wrong": per seed, the simulator's drive, its LiDAR plane
# map, and wrong copies of it (20 % of the used planes moved by 0.1 / 0.2 / 0.3 m along their
# normal, or rotated by 2 degrees; scripts/corrupt_planes.py); then ATE (no alignment: the map
# fixes the frame) of `planeloc run --deterministic` with each map and with --no-planes (VO).
# Also a "noisy" map: built from the GT poses with 5 cm / 0.2 deg noise (scripts/noisy_poses.py).
# And "refined": the same noisy poses refined by `planeloc map refine-poses` (scan-to-scan ICP in a
# pose graph with the noisy poses as priors) before the map is built.
# And "oracle": the clean map without the planes the wrong maps corrupt (corrupt_planes.py
# --remove), the best a tracker that disables exactly the wrong planes can do.
# Prints one table row per seed: seed vo clean move0.1 move0.2 move0.3 rot2 oracle noisy refined
# (metres).
#
# Usage: scripts/bench_wrong_map.sh [--preset tiny|small] [--seeds "3 11 21"] [--out DIR]
#        [--config FILE] [--tag NAME] [--init-sigma "S_XY S_Z S_YAW_DEG"] [--kinds "clean move0.2"]
#        [--draws K]
# --kinds runs a subset of the columns (ablations: scripts/bench_ablation.sh).
# --draws K: each plane-map cell is the mean over the map as it is and K copies with every plane
# offset by N(0, 0.5 mm) (corrupt_planes.py --jitter, seeds 1..K): the tracker is chaotic in its
# map, one run scatters by about +-10 % (docs/experiments.md); the runs are listed in
# DIR/<preset>-<seed>/<tag>/draws.txt.
# The plane-mode runs start from the exact GT pose with --init-sigma "0 0 0" by default, so the
# numbers measure the association alone (a coarse start adds the map lock: pass the prior).
# Data (simulator output, maps) is reused from DIR/<preset>-<seed>/ when present; runs go to
# DIR/<preset>-<seed>/<tag>/ (tag "run" by default; PLANELOC_BIN picks another binary).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
planeloc="${PLANELOC_BIN:-${PLANELOC_BUILD_DIR:-$root/build}/bin/planeloc}"
preset=small
seeds="3 11 21"
out=/tmp/planeloc-bench-wrong-map
config=()
tag=run
init_sigma="0 0 0"
kinds="vo clean move0.1 move0.2 move0.3 rot2 oracle noisy refined"
draws=0
while [ $# -gt 0 ]; do
  case "$1" in
    --preset) preset="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --config) config=(--config "$2"); shift 2 ;;
    --tag) tag="$2"; shift 2 ;;
    --init-sigma) init_sigma="$2"; shift 2 ;;
    --kinds) kinds="$2"; shift 2 ;;
    --draws) draws="$2"; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "bench_wrong_map.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
ate() {  # ATE RMSE of a trajectory, metres
  "$planeloc" eval --gt "$1" --est "$2" --align none --json "$2.ate.json" >/dev/null
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("%.4f" % d["ape"]["rmse"])' \
    "$2.ate.json"
}
echo "preset $preset, binary $planeloc"
echo "seed $kinds"
for seed in $seeds; do
  d="$out/$preset-$seed"
  mkdir -p "$d"
  if [ ! -f "$d/planes.json" ]; then
    if [ ! -f "$d/sim/poses/00.txt" ]; then
      "$planeloc" sim --out "$d/sim" --preset "$preset" --seed "$seed" --force >"$d/log.txt" 2>&1
    fi
    "$planeloc" map build --sequence "$d/sim/sequences/00" --poses "$d/sim/poses/00.txt" \
      --out "$d/map.pcd" --voxel 0.10 >>"$d/log.txt" 2>&1
    "$planeloc" map planes --map "$d/map.pcd" --out "$d/planes.json" >>"$d/log.txt" 2>&1
  fi
  for kind in move0.1 move0.2 move0.3 rot2 oracle; do
    case "$kind" in
      move*) arg=(--move "${kind#move}") ;;
      rot*) arg=(--rotate-deg "${kind#rot}") ;;
      oracle) arg=(--remove) ;;
    esac
    python3 "$root/scripts/corrupt_planes.py" "$d/planes.json" "$d/planes_$kind.json" \
      --seed "$seed" --fraction 0.2 "${arg[@]}" 2>>"$d/log.txt"
  done
  # Noisy map: the LiDAR map accumulated from poses with 5 cm / 0.2 deg noise per axis.
  if [[ " $kinds " == *" noisy "* || " $kinds " == *" refined "* ]] &&
    [ ! -f "$d/poses_noisy.txt" ]; then
    python3 "$root/scripts/noisy_poses.py" "$d/sim/poses/00.txt" "$d/poses_noisy.txt" \
      --seed "$seed" --sigma-t 0.05 --sigma-r-deg 0.2
  fi
  if [[ " $kinds " == *" refined "* && ! -f "$d/planes_refined.json" ]]; then
    "$planeloc" map refine-poses --sequence "$d/sim/sequences/00" --poses "$d/poses_noisy.txt" \
      --prior-sigma 0.05 0.2 --out "$d/poses_refined.txt" >>"$d/log.txt" 2>&1
    "$planeloc" map build --sequence "$d/sim/sequences/00" --poses "$d/poses_refined.txt" \
      --out "$d/map_refined.pcd" --voxel 0.10 >>"$d/log.txt" 2>&1
    "$planeloc" map planes --map "$d/map_refined.pcd" --out "$d/planes_refined.json" \
      >>"$d/log.txt" 2>&1
  fi
  if [[ " $kinds " == *" noisy "* && ! -f "$d/planes_noisy.json" ]]; then
    "$planeloc" map build --sequence "$d/sim/sequences/00" --poses "$d/poses_noisy.txt" \
      --out "$d/map_noisy.pcd" --voxel 0.10 >>"$d/log.txt" 2>&1
    "$planeloc" map planes --map "$d/map_noisy.pcd" --out "$d/planes_noisy.json" >>"$d/log.txt" 2>&1
  fi
  seq="$d/sim/sequences/00"
  poses="$d/sim/poses/00.txt"
  r="$d/$tag"
  mkdir -p "$r"
  [ "$draws" -gt 0 ] && : >"$r/draws.txt"
  row="$seed"
  for kind in $kinds; do
    case "$kind" in
      vo) map="" ;;
      clean) map="$d/planes.json" ;;
      *) map="$d/planes_$kind.json" ;;
    esac
    values=()
    for draw in $(seq 0 "$draws"); do
      [ -n "$map" ] || [ "$draw" = 0 ] || break  # VO does not depend on a map
      name="$kind"
      if [ -z "$map" ]; then
        maparg=(--no-planes)
      elif [ "$draw" = 0 ]; then
        maparg=(--planes "$map" --init-sigma "$init_sigma")
      else
        name="$kind.draw$draw"
        python3 "$root/scripts/corrupt_planes.py" "$map" "$r/planes_$name.json" --seed "$draw" \
          --jitter 0.0005
        maparg=(--planes "$r/planes_$name.json" --init-sigma "$init_sigma")
      fi
      "$planeloc" run --sequence "$seq" --init-pose-from "$poses" "${maparg[@]}" "${config[@]}" \
        --deterministic --out "$r/traj_$name.txt" --stats "$r/stats_$name.jsonl" \
        >"$r/run_$name.log" 2>&1
      values+=("$(ate "$poses" "$r/traj_$name.txt")")
    done
    [ "$draws" -gt 0 ] && echo "$kind ${values[*]}" >>"$r/draws.txt"
    mean='import sys; v = [float(x) for x in sys.argv[1:]]; print("%.4f" % (sum(v) / len(v)))'
    row="$row $(python3 -c "$mean" "${values[@]}")"
  done
  echo "$row"
done
