#!/usr/bin/env bash
# planeloc end to end: set-up, build, then
#   data  -> LiDAR map (planeloc map build) -> plane map (planeloc map planes)
#         -> stereo localization in the plane map, and the visual-only baseline (planeloc run)
#         -> evaluation of both against ground truth (planeloc eval)
#         -> one HTML page of both runs (planeloc report): out/demo/report.html.
# With no arguments it runs on the built-in synthetic town (`planeloc sim --preset small`).
#
# Usage: scripts/demo.sh [--sequence KITTI_SEQ_DIR --poses GT_POSES] [--out DIR] [--preset NAME]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$root/out/demo"
sequence=""
poses=""
preset="small"
while [ $# -gt 0 ]; do
  case "$1" in
    --sequence) sequence="$2"; shift 2 ;;
    --poses) poses="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --preset) preset="$2"; shift 2 ;;
    -h|--help) sed -n '2,8p' "$0"; exit 0 ;;
    *) echo "demo.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [ -n "$sequence" ] && [ -z "$poses" ]; then
  echo "demo.sh: --sequence needs --poses (ground-truth KITTI poses for map building and evaluation)" >&2
  exit 2
fi

"$root/scripts/setup.sh"
"$root/scripts/build.sh"
planeloc="${PLANELOC_BUILD_DIR:-$root/build}/bin/planeloc"
mkdir -p "$out"

step() { echo; echo "=== $*"; }

if [ -z "$sequence" ]; then
  step "1/7 synthetic town (preset $preset, seed 7)"
  "$planeloc" sim --out "$out/sim" --preset "$preset" --seed 7 --force
  sequence="$out/sim/sequences/00"
  poses="$out/sim/poses/00.txt"
fi

step "2/7 LiDAR map from the scans and ground-truth poses"
"$planeloc" map build --sequence "$sequence" --poses "$poses" --out "$out/map.pcd" --voxel 0.10

step "3/7 plane map by tensor voting + k-means"
gt=()
if [ -f "$out/sim/world/planes_gt.json" ] && [ "$sequence" = "$out/sim/sequences/00" ]; then
  gt=(--gt "$out/sim/world/planes_gt.json")  # the simulator's GT planes: accuracy in the log
fi
"$planeloc" map planes --map "$out/map.pcd" --out "$out/planes.json" --ply "$out/planes.ply" \
  "${gt[@]}"

step "4/7 stereo localization in the plane map (point-to-plane constraints on)"
"$planeloc" run --sequence "$sequence" --init-pose-from "$poses" --planes "$out/planes.json" \
  --out "$out/traj_planes.txt" --stats "$out/stats_planes.jsonl" --report-dir "$out/run_planes" \
  --map-update "$out/map_update.json"

step "5/7 stereo tracking, plane constraints off (ORB-SLAM2-like baseline), same frames"
"$planeloc" run --sequence "$sequence" --init-pose-from "$poses" --no-planes \
  --out "$out/traj_vo.txt" --stats "$out/stats_vo.jsonl" --report-dir "$out/run_vo"

step "6/7 evaluation against ground truth"
# KITTI drift needs at least one 100 m segment: the tiny preset (60 m) has none.
drift=(--kitti-drift)
path_m=$(awk 'NR>1{dx=$4-x;dy=$8-y;dz=$12-z;s+=sqrt(dx*dx+dy*dy+dz*dz)}{x=$4;y=$8;z=$12}END{printf "%d", s}' "$poses")
if [ "$path_m" -lt 100 ]; then drift=(); echo "(path ${path_m} m < 100 m: no KITTI drift)"; fi
for run in planes vo; do
  echo "--- $run: ATE in the map frame (no alignment: the map fixes the frame)"
  "$planeloc" eval --gt "$poses" --est "$out/traj_$run.txt" --align none --json "$out/ate_$run.json"
  echo "--- $run: SE(3)-aligned, 2-D (x-z), relative error"
  "$planeloc" eval --gt "$poses" --est "$out/traj_$run.txt" --align se3 --plane xz \
    --rpe-delta 1 --rpe-unit frames "${drift[@]}" \
    --json "$out/eval_$run.json" --plot "$out/eval_$run.png"
done
echo "--- both runs in one plot (map frame, no alignment)"
"$planeloc" eval --gt "$poses" --est "$out/traj_planes.txt" --also-est "$out/traj_vo.txt" \
  --align none --plot "$out/eval_both.png" >/dev/null

step "7/7 HTML report of both runs against ground truth"
"$planeloc" report --run "$out/run_planes" --compare "$out/run_vo" --gt "$poses" \
  --out "$out/report.html" --title "planeloc demo: plane mode vs VO"

echo
echo "Outputs in $out: map.pcd, planes.json, planes.ply, traj_{planes,vo}.txt, stats_{planes,vo}.jsonl,"
echo "ate_{planes,vo}.json, eval_{planes,vo}.json, eval_{planes,vo,both}.png, run_{planes,vo}/,"
echo "map_update.json (what the run learned about each plane; the report colours the planes by it)"
echo
echo "Report (open in a browser, works offline): $out/report.html"
