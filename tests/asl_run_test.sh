#!/usr/bin/env bash
# `planeloc run --sequence` on the ASL / EuRoC layout (issue 35 item 1): the simulator's tiny
# sequence written in that layout by scripts/kitti_to_asl.py (an ideal rig, rectified on load by
# the identity) gives the trajectory of the KITTI-layout original, the layout is said in one
# line, `eval --format euroc` reads the ground truth's csv against the TUM output with the APE of
# the KITTI files, and a broken calibration is exit 2 naming the file.
# Usage: tests/asl_run_test.sh PLANELOC_BINARY [SOURCE_DIR]
set -uo pipefail
planeloc="$1"
src="${2:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"
find_python

run_step sim "$planeloc" sim --out "$tmp/sim" --preset tiny --seed 1 --frames 30 --force
seq="$tmp/sim/sequences/00"
run_step kitti_to_asl "$python" "$src/scripts/kitti_to_asl.py" "$seq" "$tmp/asl" \
  --poses "$tmp/sim/poses/00.txt"
"$planeloc" run --sequence "$tmp/asl" --no-planes --deterministic --out "$tmp/asl.txt" \
  >"$tmp/asl.log" 2>&1
check "run on the ASL folder exits 0" test $? -eq 0
"$planeloc" run --sequence "$tmp/asl" --no-planes --deterministic --format tum \
  --out "$tmp/asl.tum" >"$tmp/asl_tum.log" 2>&1
check "run --format tum on the ASL folder exits 0" test $? -eq 0
"$planeloc" run --sequence "$seq" --no-planes --deterministic --out "$tmp/kitti.txt" \
  >"$tmp/kitti.log" 2>&1
check "run on the KITTI original exits 0" test $? -eq 0
check "the layout is said in one line" grep -q "ASL/EuRoC layout, 30 stereo frames" "$tmp/asl.log"
check "one pose per frame (30)" test "$(grep -c . "$tmp/asl.txt")" -eq 30
# The rectification of an ideal rig is the identity up to cv::stereoRectify's rounding (fx
# 707.0912 -> 707.0912 + 2e-5): measured 1.2 um RMSE between the two trajectories here (2.4 um
# on all 60 frames of tiny seed 3).
"$planeloc" eval --gt "$tmp/kitti.txt" --est "$tmp/asl.txt" --align none --json "$tmp/eval.json" \
  >/dev/null 2>&1
rmse=$("$python" -c "import json,sys; print(json.load(open(sys.argv[1]))['ape']['rmse'])" "$tmp/eval.json" 2>/dev/null || echo 1)
check "the same trajectory as the KITTI original (RMSE $rmse m < 1e-4)" \
  "$python" -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-4 else 1)" "$rmse"

# eval --format euroc: the ASL ground truth's csv against the TUM output (the dataset's clock),
# the same APE as the KITTI files of the same run, to the trajectories' 1.2 um.
ape() { "$python" -c "import json,sys; print(json.load(open(sys.argv[1]))['ape']['rmse'])" "$1"; }
"$planeloc" eval --format euroc --gt "$tmp/asl/mav0/state_groundtruth_estimate0/data.csv" \
  --est "$tmp/asl.tum" --align se3 --json "$tmp/euroc.json" >"$tmp/euroc.log" 2>&1
check "eval --format euroc exits 0" test $? -eq 0
"$planeloc" eval --gt "$tmp/sim/poses/00.txt" --est "$tmp/kitti.txt" --align se3 \
  --json "$tmp/kitti_eval.json" >/dev/null 2>&1
euroc_ape=$(ape "$tmp/euroc.json" 2>/dev/null || echo -1)
kitti_ape=$(ape "$tmp/kitti_eval.json" 2>/dev/null || echo 1)
check "eval --format euroc pairs all 30 frames" grep -q '"associated_poses": 30' "$tmp/euroc.json"
check "the same APE as KITTI eval of the original ($euroc_ape vs $kitti_ape m)" \
  "$python" -c "import sys; sys.exit(0 if abs(float(sys.argv[1]) - float(sys.argv[2])) < 1e-4 else 1)" \
  "$euroc_ape" "$kitti_ape"

# Plane mode from the ground truth's csv (the body pose at frame 0's time through T_BS), exact
# start: the trajectory of the KITTI run started from the pose file.
gt_csv="$tmp/asl/mav0/state_groundtruth_estimate0/data.csv"
planes="$tmp/sim/world/planes_gt.json"
"$planeloc" run --sequence "$tmp/asl" --init-pose-from "$gt_csv" --planes "$planes" \
  --init-sigma "0 0 0" --deterministic --out "$tmp/asl_planes.txt" >"$tmp/asl_planes.log" 2>&1
check "plane mode on the ASL folder from its ground-truth csv exits 0" test $? -eq 0
"$planeloc" run --sequence "$seq" --init-pose-from "$tmp/sim/poses/00.txt" --planes "$planes" \
  --init-sigma "0 0 0" --deterministic --out "$tmp/kitti_planes.txt" >/dev/null 2>&1
"$planeloc" eval --gt "$tmp/kitti_planes.txt" --est "$tmp/asl_planes.txt" --align none \
  --json "$tmp/planes_eval.json" >/dev/null 2>&1
rmse=$(ape "$tmp/planes_eval.json" 2>/dev/null || echo 1)
check "the plane-mode trajectory of the KITTI original (RMSE $rmse m < 1e-4)" \
  "$python" -c "import sys; sys.exit(0 if float(sys.argv[1]) < 1e-4 else 1)" "$rmse"
"$planeloc" run --sequence "$seq" --init-pose-from "$gt_csv" --no-planes --out "$tmp/x.txt" \
  >"$tmp/csv_kitti.log" 2>&1
code=$?
check "a EuRoC csv with a KITTI --sequence is exit 2 naming the csv (got $code)" \
  test "$code" -eq 2 -a -n "$(grep -l "data.csv" "$tmp/csv_kitti.log")"

# A calibration that is not rigid: exit 2, the file named.
sed -i 's/data: \[1.0, 0.0, 0.0,/data: [2.0, 0.0, 0.0,/' "$tmp/asl/mav0/cam1/sensor.yaml"
"$planeloc" run --sequence "$tmp/asl" --no-planes --out "$tmp/bad.txt" >"$tmp/bad.log" 2>&1
code=$?
check "a broken sensor.yaml is exit 2 (got $code)" test "$code" -eq 2
check "the error names cam1/sensor.yaml" grep -q "cam1/sensor.yaml" "$tmp/bad.log"
exit "$fail"
