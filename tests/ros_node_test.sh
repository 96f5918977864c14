#!/usr/bin/env bash
# Issue 14: planeloc_node in ROS 1 on localhost. A rosmaster on a free port, planeloc_node with
# the tiny preset's plane map (exact start, --deterministic), and planeloc_stereo_player playing
# a bag of 12 tiny frames (`planeloc convert kitti-to-bag`) at 4 Hz; the poses the node publishes
# on ~odometry must be those of `planeloc run --deterministic` on the same frames within 1e-6 m and
# 1e-6 per rotation entry, and the plane markers must arrive (latched). Twice: the node started
# directly, then through apps/ros/launch/planeloc.launch (roslaunch, with a package folder of its
# own that holds package.xml and the node, so that another build tree's node cannot be picked).
# Usage: ros_node_test.sh SOURCE_DIR path/to/planeloc path/to/planeloc_node
#        path/to/planeloc_stereo_player
set -u
source_dir="$1"
planeloc="$2"
node="$3"
player="$4"
work="$(mktemp -d "${TMPDIR:-/tmp}/planeloc-rosnode.XXXXXX")"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  wait 2>/dev/null
  [ -n "${PLANELOC_KEEP_TEST_DIR:-}" ] || rm -rf "$work"
}
trap cleanup EXIT
passed=0
fail() {
  echo "FAIL $1"
  [ -n "${2:-}" ] && tail -20 "$2"
  echo "ros node: $passed passed, 1 failed"
  exit 1
}

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
# check NAME: plays the bag to the running node and compares what it published with run.txt.
check() {
  local name="$1"
  "$player" "$work/tiny.bag" 4 /planeloc "$work/$name.txt" 120 >"$work/$name.player.log" 2>&1 \
    || fail "$name: player: 12 poses back from the node" "$work/$name.node.log"
  cat "$work/$name.player.log"
  grep -q "12 poses received" "$work/$name.player.log" || fail "$name: 12 poses" \
    "$work/$name.player.log"
  grep -Eq " [1-9][0-9]* plane markers" "$work/$name.player.log" || fail \
    "$name: latched plane markers" "$work/$name.player.log"
  /usr/bin/python3 - "$work/run.txt" "$work/$name.txt" <<'PY' || fail "$name: node poses == run poses"
import math, sys
run = [list(map(float, l.split())) for l in open(sys.argv[1])]
node = [list(map(float, l.split())) for l in open(sys.argv[2])]
assert len(run) == len(node) == 12, (len(run), len(node))
worst_t = worst_r = 0.0
for a, b in zip(run, node):
    worst_t = max(worst_t, math.dist([a[3], a[7], a[11]], [b[3], b[7], b[11]]))
    worst_r = max(worst_r, max(abs(x - y) for x, y in zip(a, b)))
print(f"node vs run: largest position difference {worst_t:.3e} m, rotation entry {worst_r:.3e}")
# The node runs the CLI's code on the same frames with --deterministic: measured 3.7e-9 m and
# 3.7e-9 (2026-12-04, `ctest -R ros.node`; the printed poses' precision). A node that publishes
# visual odometry's poses instead of the map-corrected ones differs by 1.6 cm on these 12 frames
# (scripts/mutants/11-ros-vo-frame.patch), which the old 1 cm bound barely caught.
sys.exit(0 if worst_t < 1e-6 and worst_r < 1e-6 else 1)
PY
  passed=$((passed + 1))
}

"$node" __name:=planeloc _planes:="$planes" _init_pose:="1 0 0 0 0 1 0 0 0 0 1 0" \
  _init_sigma:="0 0 0" _deterministic:=true _queue_size:=100 \
  left/image_rect:=/stereo/left/image_rect right/image_rect:=/stereo/right/image_rect \
  left/camera_info:=/stereo/left/camera_info right/camera_info:=/stereo/right/camera_info \
  >"$work/direct.node.log" 2>&1 &
node_pid=$!
pids+=($node_pid)
check direct
kill -INT "$node_pid"  # roscpp shuts down cleanly (unregisters) on SIGINT
wait "$node_pid" 2>/dev/null

mkdir -p "$work/pkg"
cp "$source_dir/package.xml" "$work/pkg/"
ln -s "$(realpath "$node")" "$work/pkg/planeloc_node"
ROS_PACKAGE_PATH="$work/pkg" roslaunch "$source_dir/apps/ros/launch/planeloc.launch" \
  planes:="$planes" deterministic:=true >"$work/roslaunch.node.log" 2>&1 </dev/null &
pids+=($!)
check roslaunch
echo "ros node: $passed passed, 0 failed"
