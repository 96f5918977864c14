#!/usr/bin/env bash
# Issue 14: rosbag input. `planeloc convert kitti-to-bag` writes 12 frames of the tiny preset as
# a bag (mono8, and png-compressed); `planeloc run --bag` on it gives the trajectory of `planeloc
# run --sequence` on the folder byte for byte (--deterministic, same plane map, exact start); bad
# bags and flags exit 2 naming the topic, file or flag. Registered only in builds with ROS.
# Usage: rosbag_cli_test.sh path/to/planeloc
set -u
planeloc="$1"
work="$(mktemp -d "${TMPDIR:-/tmp}/planeloc-rosbag.XXXXXX")"
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL $1"; [ -n "${2:-}" ] && tail -5 "$2"; }

# expect_error NAME EXPECTED_SUBSTRING -- command...: exit 2 and the substring in the output.
expect_error() {
  local name="$1" needle="$2"
  shift 3
  local output code
  output="$("$@" 2>&1)"
  code=$?
  if [ "$code" -eq 2 ] && grep -qF -- "$needle" <<<"$output"; then
    pass
  else
    failed=$((failed + 1))
    echo "FAIL $name: exit $code, expected 2 and '$needle' in:"
    echo "$output" | tail -3
  fi
}
# step NAME command...: exit 0 (log in $work/NAME.log).
step() {
  local name="$1"
  shift
  if "$@" >"$work/$name.log" 2>&1; then pass; else fail "$name (exit $?)" "$work/$name.log"; fi
}

step sim "$planeloc" sim --out "$work/sim" --preset tiny --frames 12
seq="$work/sim/sequences/00"
planes="$work/sim/world/planes_gt.json"
step convert "$planeloc" convert kitti-to-bag --sequence "$seq" --out "$work/tiny.bag"
step convert_png "$planeloc" convert kitti-to-bag --sequence "$seq" --out "$work/tiny_png.bag" \
  --encoding png
topics=(--left-topic /stereo/left/image_rect --right-topic /stereo/right/image_rect)
common=(--planes "$planes" --init-sigma "0 0 0" --deterministic)
step run_folder "$planeloc" run --sequence "$seq" "${common[@]}" --out "$work/folder.txt"
step run_bag "$planeloc" run --bag "$work/tiny.bag" "${topics[@]}" "${common[@]}" \
  --out "$work/bag.txt"
step run_png "$planeloc" run --bag "$work/tiny_png.bag" "${topics[@]}" \
  --camera-info-topics /stereo/left/camera_info /stereo/right/camera_info "${common[@]}" \
  --out "$work/png.txt"
if [ "$(wc -l <"$work/bag.txt")" -eq 12 ] && cmp -s "$work/folder.txt" "$work/bag.txt"; then
  pass
else
  fail "run --bag poses == run --sequence poses (12 lines)"
fi
if cmp -s "$work/folder.txt" "$work/png.txt"; then pass; else fail "png bag poses == folder's"; fi
grep -q "12 stereo frames" "$work/run_bag.log" && pass || fail "12 stereo frames logged" \
  "$work/run_bag.log"

# Bad bags and flags.
expect_error "missing topic" "/cam1/image_raw" -- "$planeloc" run --bag "$work/tiny.bag" \
  --left-topic /stereo/left/image_rect --right-topic /cam1/image_raw --no-planes \
  --out "$work/x.txt"
expect_error "info topic of another type" "/stereo/left/image_rect holds sensor_msgs/Image" -- \
  "$planeloc" run --bag "$work/tiny.bag" "${topics[@]}" --no-planes --out "$work/x.txt" \
  --camera-info-topics /stereo/left/image_rect /stereo/right/camera_info
expect_error "no topics" "--left-topic" -- "$planeloc" run --bag "$work/tiny.bag" --no-planes \
  --out "$work/x.txt"
expect_error "bag and sequence" "--sequence and --bag" -- "$planeloc" run --bag "$work/tiny.bag" \
  --sequence "$seq" "${topics[@]}" --no-planes --out "$work/x.txt"
printf 'not a bag\n' >"$work/text.bag"
expect_error "not a bag" "text.bag" -- "$planeloc" run --bag "$work/text.bag" "${topics[@]}" \
  --no-planes --out "$work/x.txt"
expect_error "missing bag" "absent.bag" -- "$planeloc" run --bag "$work/absent.bag" \
  "${topics[@]}" --no-planes --out "$work/x.txt"
expect_error "negative tolerance" "--pair-tolerance" -- "$planeloc" run --bag "$work/tiny.bag" \
  "${topics[@]}" --pair-tolerance -1 --no-planes --out "$work/x.txt"
expect_error "convert to a missing folder" "--out" -- "$planeloc" convert kitti-to-bag \
  --sequence "$seq" --out "$work/no/such/dir/x.bag"

echo "rosbag cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
