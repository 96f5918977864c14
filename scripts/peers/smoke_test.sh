#!/usr/bin/env bash
# Smoke test of the ORB-SLAM2 peer (NOT registered in ctest/CI). Exit 77 (skip) unless
# scripts/peers/build_orbslam2.sh has completed. Otherwise: a sim drive the benchmark does not
# evaluate on (planeloc sim --preset small --seed 5, cached in build-peers/smoke/), the settings
# generator, the runner, and planeloc eval (APE, alignment none and se3) against the sim's GT.
# Checks: the runner exits 0, one pose line and one CSV row per frame, no lost frame, ATE (se3)
# RMSE below SMOKE_MAX_ATE_M (default 1.0 m). Prints the numbers; exit 1 on a failed check.
#   SMOKE_FRAMES=N   only the first N frames of the sim (default: all 300)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
peers="$repo/build-peers"
planeloc="${PLANELOC_BIN:-$repo/build/bin/planeloc}"
runner="$peers/bin/orbslam2_stereo_kitti"
voc="${SMOKE_VOCABULARY:-$peers/vocabulary/orbvoc.txt}"
max_ate="${SMOKE_MAX_ATE_M:-1.0}"

if [[ ! -f "$peers/.orbslam2.stamp" || ! -x "$runner" || ! -s "$voc" ]]; then
  echo "smoke_test: SKIP: ORB-SLAM2 peer not built (run scripts/peers/build_orbslam2.sh)" >&2
  exit 77
fi
if [[ ! -x "$planeloc" ]]; then
  echo "smoke_test: SKIP: planeloc CLI not built ($planeloc)" >&2
  exit 77
fi

work="$peers/smoke"
sim="$work/sim-small-seed5"
mkdir -p "$work"
if [[ ! -f "$sim/poses/00.txt" ]]; then
  rm -rf "$sim.partial"
  echo "smoke_test: planeloc sim --preset small --seed 5 ..." >&2
  nice -n 10 "$planeloc" sim --preset small --seed 5 --out "$sim.partial" >"$work/sim.log" 2>&1
  rm -rf "$sim" && mv "$sim.partial" "$sim"
fi
seq="$sim/sequences/00"
gt="$sim/poses/00.txt"
if [[ -n "${SMOKE_FRAMES:-}" ]]; then
  cut="$work/seq-first$SMOKE_FRAMES"
  rm -rf "$cut" && mkdir -p "$cut/image_0" "$cut/image_1"
  cp "$seq/calib.txt" "$cut/"
  head -n "$SMOKE_FRAMES" "$seq/times.txt" >"$cut/times.txt"
  for ((i = 0; i < SMOKE_FRAMES; i++)); do
    f=$(printf '%06d.png' "$i")
    ln -s "$seq/image_0/$f" "$cut/image_0/$f"
    ln -s "$seq/image_1/$f" "$cut/image_1/$f"
  done
  head -n "$SMOKE_FRAMES" "$gt" >"$work/gt-first$SMOKE_FRAMES.txt"
  seq="$cut"
  gt="$work/gt-first$SMOKE_FRAMES.txt"
fi
frames=$(wc -l <"$seq/times.txt")

python3 "$here/orbslam2_settings.py" "$seq" -o "$work/settings.yaml"
est="$work/orbslam2_poses.txt"
t0=$(date +%s.%N)
nice -n 10 "$runner" "$voc" "$work/settings.yaml" "$seq" "$est" >"$work/runner.log" 2>&1 || {
  tail -n 20 "$work/runner.log" >&2
  echo "smoke_test: FAIL: runner exited $?" >&2
  exit 1
}
wall=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$t0" "$(date +%s.%N)")

fail=0
[[ $(wc -l <"$est") == "$frames" ]] || { echo "smoke_test: FAIL: $(wc -l <"$est") pose lines for $frames frames" >&2; fail=1; }
[[ $(($(wc -l <"$est.timing.csv") - 1)) == "$frames" ]] || { echo "smoke_test: FAIL: timing CSV rows != frames" >&2; fail=1; }

for align in none se3; do
  "$planeloc" eval --gt "$gt" --est "$est" --align "$align" --json "$work/ate-$align.json" >"$work/eval-$align.log" 2>&1 \
    || { cat "$work/eval-$align.log" >&2; echo "smoke_test: FAIL: planeloc eval --align $align" >&2; exit 1; }
done
python3 - "$work" "$est.timing.csv" "$frames" "$wall" "$max_ate" <<'EOF' || fail=1
import csv, json, statistics, sys
work, timing, frames, wall, max_ate = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])

def rmse(path):
    def find(node):
        if isinstance(node, dict):
            for key, value in node.items():
                if key.lower() == "rmse" and isinstance(value, (int, float)):
                    return float(value)
            for value in node.values():
                r = find(value)
                if r is not None:
                    return r
        elif isinstance(node, list):
            for value in node:
                r = find(value)
                if r is not None:
                    return r
        return None
    with open(path) as f:
        return find(json.load(f))

rows = list(csv.DictReader(open(timing)))
track = [float(r["track_ms"]) for r in rows]
decode = [float(r["decode_ms"]) for r in rows]
lost = sum(1 for r in rows if r["pose_valid"] != "1")
resets = max(int(r["map_id"]) for r in rows)
ate_none, ate_se3 = rmse(f"{work}/ate-none.json"), rmse(f"{work}/ate-se3.json")
print(f"smoke_test: {frames} frames, runner wall {wall:.1f} s incl. vocabulary load "
      f"({frames / (sum(track) / 1000):.1f} fps on TrackStereo alone), median TrackStereo "
      f"{statistics.median(track):.1f} ms, median decode {statistics.median(decode):.1f} ms, "
      f"frames without a pose {lost}, map resets {resets}")
print(f"smoke_test: ATE RMSE align none {ate_none:.3f} m, align se3 {ate_se3:.3f} m")
ok = lost == 0 and ate_se3 is not None and ate_se3 < max_ate
if not ok:
    print(f"smoke_test: FAIL: lost frames {lost} or ATE(se3) >= {max_ate} m", file=sys.stderr)
sys.exit(0 if ok else 1)
EOF
if ((fail)); then exit 1; fi
echo "smoke_test: PASS (logs and outputs in $work)"
