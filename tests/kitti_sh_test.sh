#!/usr/bin/env bash
# scripts/kitti.sh end to end on a synthetic sequence written in the KITTI odometry layout with
# the KITTI-07 calibration (the simulator's tiny preset, 60 frames): every step runs, the outputs
# are complete, plane mode beats the baseline on the same frames, and bad input is exit 2 naming
# the missing path.
# Usage: tests/kitti_sh_test.sh PLANELOC_BINARY [SOURCE_DIR]
set -uo pipefail
planeloc="$1"
src="${2:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail=0
check() {  # check DESCRIPTION COMMAND...
  local what="$1"; shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fail=1; fi
}

"$planeloc" sim --out "$tmp/sim" --preset tiny --seed 1 --force >"$tmp/sim.log" 2>&1 || {
  echo "FAIL sim"; cat "$tmp/sim.log"; exit 1; }
seq="$tmp/sim/sequences/00"
poses="$tmp/sim/poses/00.txt"
check "the sequence carries the KITTI-07 calibration (fx 707.0912)" \
  grep -q "^P0: 7.070912000000e+02" "$seq/calib.txt"

PLANELOC_BIN="$planeloc" bash "$src/scripts/kitti.sh" "$seq" "$poses" --out "$tmp/out" \
  >"$tmp/kitti.log" 2>&1
rc=$?
check "kitti.sh exits 0" test "$rc" -eq 0
[ "$rc" -eq 0 ] || tail -30 "$tmp/kitti.log"
frames=$(grep -c . "$poses")
for f in map.pcd planes.json planes.ply summary.md eval_planes.png eval_vo.png; do
  check "$f written" test -s "$tmp/out/$f"
done
for run in planes vo; do
  check "traj_$run.txt has one pose per frame ($frames)" \
    test "$(grep -c . "$tmp/out/traj_$run.txt")" -eq "$frames"
done
# Numbers from the JSON the script wrote: plane mode below the baseline (measured on this
# sequence: ATE 3-D 0.045 m vs 0.084 m, 2026-12-01), and 2-D never above 3-D (it drops one axis
# of the same unaligned error).
check "plane mode's ATE below the baseline's, 2-D <= 3-D, summary rows" python3 - "$tmp/out" <<'PY'
import json, sys
out = sys.argv[1]
ate = {(run, dim): json.load(open(f"{out}/ate{dim}_{run}.json"))["ape"]["rmse"]
       for run in ("planes", "vo") for dim in ("2d", "3d")}
print("ATE", {f"{r}/{d}": round(v, 4) for (r, d), v in ate.items()})
assert ate[("planes", "3d")] < ate[("vo", "3d")], ate
assert all(ate[(r, "2d")] <= ate[(r, "3d")] + 1e-9 for r in ("planes", "vo")), ate
summary = open(f"{out}/summary.md").read()
assert "reported in the paper, not measured here" in summary
assert f"{ate[('planes', '2d')]:.3f} m" in summary, summary
PY

# Bad input: exit 2 and the missing path named.
mkdir -p "$tmp/noscan"
cp "$seq/calib.txt" "$seq/times.txt" "$tmp/noscan/"
PLANELOC_BIN="$planeloc" bash "$src/scripts/kitti.sh" "$tmp/noscan" "$poses" --out "$tmp/o2" \
  >"$tmp/bad1.log" 2>&1
rc=$?
check "no velodyne/: exit 2" test "$rc" -eq 2
check "no velodyne/: names the folder" grep -q "$tmp/noscan/velodyne" "$tmp/bad1.log"
PLANELOC_BIN="$planeloc" bash "$src/scripts/kitti.sh" "$seq" "$tmp/missing.txt" >"$tmp/bad2.log" 2>&1
rc=$?
check "missing poses: exit 2" test "$rc" -eq 2
check "missing poses: names the file" grep -q "$tmp/missing.txt" "$tmp/bad2.log"
bash "$src/scripts/kitti.sh" >"$tmp/bad3.log" 2>&1
check "no arguments: exit 2 with usage" test $? -eq 2
exit $fail
