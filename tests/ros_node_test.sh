#!/usr/bin/env bash
# Issue 14: planeloc_node in ROS 1 on localhost. A rosmaster on a free port, planeloc_node with
# the tiny preset's plane map (exact start, --deterministic), and planeloc_stereo_player playing
# a bag of 12 tiny frames (`planeloc convert kitti-to-bag`) at 4 Hz; the poses the node publishes
# on ~odometry must be those of `planeloc run --deterministic` on the same frames within 1 cm
# (and 0.1 degree), and the plane markers must arrive (latched).
# Usage: ros_node_test.sh path/to/planeloc path/to/planeloc_node path/to/planeloc_stereo_player
set -u
planeloc="$1"
node="$2"
player="$3"
work="$(mktemp -d "${TMPDIR:-/tmp}/planeloc-rosnode.XXXXXX")"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  wait 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL $1"; [ -n "${2:-}" ] && tail -20 "$2"; echo "ros node: 0 passed, 1 failed"; exit 1; }

"$planeloc" sim --out "$work/sim" --preset tiny --frames 12 >"$work/sim.log" 2>&1 || fail sim "$work/sim.log"
seq="$work/sim/sequences/00"
planes="$work/sim/world/planes_gt.json"
"$planeloc" convert kitti-to-bag --sequence "$seq" --out "$work/tiny.bag" >"$work/convert.log" 2>&1 \
  || fail convert "$work/convert.log"
"$planeloc" run --sequence "$seq" --planes "$planes" --init-sigma "0 0 0" --deterministic \
  --out "$work/run.txt" >"$work/run.log" 2>&1 || fail run "$work/run.log"

# A master of our own on localhost, on a port nothing else uses.
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_IP=127.0.0.1 ROS_HOME="$work/ros_home"
export ROS_LOG_DIR="$work/ros_log"
rosmaster --core -p "$port" >"$work/master.log" 2>&1 &
pids+=($!)
"$node" __name:=planeloc _planes:="$planes" _init_pose:="1 0 0 0 0 1 0 0 0 0 1 0" \
  _init_sigma:="0 0 0" _deterministic:=true _queue_size:=100 \
  left/image_rect:=/stereo/left/image_rect right/image_rect:=/stereo/right/image_rect \
  left/camera_info:=/stereo/left/camera_info right/camera_info:=/stereo/right/camera_info \
  >"$work/node.log" 2>&1 &
pids+=($!)
"$player" "$work/tiny.bag" 4 /planeloc "$work/node.txt" 120 >"$work/player.log" 2>&1 \
  || fail "player: 12 poses back from the node" "$work/node.log"
cat "$work/player.log"
grep -q "12 poses received" "$work/player.log" || fail "12 poses" "$work/player.log"
grep -Eq " [1-9][0-9]* plane markers" "$work/player.log" || fail "latched plane markers" \
  "$work/player.log"
/usr/bin/python3 - "$work/run.txt" "$work/node.txt" <<'PY' || fail "node poses == run poses"
import math, sys
run = [list(map(float, l.split())) for l in open(sys.argv[1])]
node = [list(map(float, l.split())) for l in open(sys.argv[2])]
assert len(run) == len(node) == 12, (len(run), len(node))
worst_t = worst_r = 0.0
for a, b in zip(run, node):
    worst_t = max(worst_t, math.dist([a[3], a[7], a[11]], [b[3], b[7], b[11]]))
    worst_r = max(worst_r, max(abs(x - y) for x, y in zip(a, b)))
print(f"node vs run: largest position difference {worst_t:.3e} m, rotation entry {worst_r:.3e}")
sys.exit(0 if worst_t < 0.01 and worst_r < 0.0017 else 1)
PY
echo "ros node: 1 passed, 0 failed"
