#!/usr/bin/env bash
# Issue 15 end to end on the simulator's tiny preset (60 frames): `map tile` from a map and
# `map build --tiles-out` from the scans give the same tiles; `map planes --tiles` gives the
# untiled plane map (scripts/compare_plane_maps.py: the planes >= 20 m^2 matched within 0.5 deg
# and 3 cm, at most one split inside a tile) with at least the untiled GT recall; `mpirun -n 2 --oversubscribe`
# writes a byte-identical planes.json (skipped when planeloc or the machine has no MPI); a broken tile
# fails the run (exit 2) naming the tile.
# Usage: tests/map_tiles_test.sh PLANELOC_BINARY SOURCE_DIR
set -uo pipefail
planeloc="$1"
src="$2"
tmp="$(mktemp -d)"
[ -n "${KEEP_TMP:-}" ] || trap 'rm -rf "$tmp"' EXIT; echo "work dir: $tmp"
fail=0
check() {  # check DESCRIPTION COMMAND...
  local what="$1"; shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fail=1; fi
}
run() {  # run LOG COMMAND...: quiet unless it fails
  local log="$1"; shift
  "$@" >"$log" 2>&1 || { echo "FAIL $* (exit $?)"; tail -20 "$log"; exit 1; }
}

run "$tmp/sim.log" "$planeloc" sim --out "$tmp/sim" --preset tiny --seed 1 --force
seq="$tmp/sim/sequences/00"
poses="$tmp/sim/poses/00.txt"
gt="$tmp/sim/world/planes_gt.json"
run "$tmp/build.log" "$planeloc" map build --sequence "$seq" --poses "$poses" \
  --out "$tmp/map.pcd" --voxel 0.10
# 25 m tiles so that the tiny town (~60 m of road) has several borders.
run "$tmp/tile.log" "$planeloc" map tile --map "$tmp/map.pcd" --tile-size 25 --overlap 3 \
  --out "$tmp/tiles"
run "$tmp/tiles_out.log" "$planeloc" map build --sequence "$seq" --poses "$poses" --voxel 0.10 \
  --tiles-out "$tmp/tiles_streamed" --tile-size 25 --overlap 3
tiles=$(python3 -c "import json; print(len(json.load(open('$tmp/tiles/index.json'))['tiles']))")
check "several tiles ($tiles)" test "$tiles" -ge 3
check "map build --tiles-out writes the same tiles as map tile" python3 - "$tmp" <<'PY'
import json, sys
a = json.load(open(sys.argv[1] + "/tiles/index.json"))
b = json.load(open(sys.argv[1] + "/tiles_streamed/index.json"))
ka = [(t["key"], t["core_points"]) for t in a["tiles"]]
kb = [(t["key"], t["core_points"]) for t in b["tiles"]]
sys.exit(0 if ka == kb and a["points"] == b["points"] and a["axes"] == b["axes"] else 1)
PY

run "$tmp/untiled.log" "$planeloc" map planes --map "$tmp/map.pcd" --out "$tmp/untiled.json" \
  --gt "$gt"
run "$tmp/tiled.log" "$planeloc" map planes --tiles "$tmp/tiles" --out "$tmp/tiled.json" \
  --gt "$gt"
# What map build read and dropped travels with the map (issue 37): the .pcd's header into
# planes.json's stats, the streamed tiles' index.json; both builds read the same scans.
check "map build's scan counts in planes.json and in the streamed tiles' index" \
  python3 - "$tmp/untiled.json" "$tmp/tiles_streamed/index.json" "$poses" <<'PY'
import json, sys
untiled = json.load(open(sys.argv[1]))["stats"]["map_build"]
streamed = json.load(open(sys.argv[2]))["map_build"]
frames = sum(1 for line in open(sys.argv[3]) if line.strip())
keys = ("frames", "scans", "missing_scans", "empty_scans", "scan_points", "non_finite_points",
        "out_of_range_points")
ok = untiled["scans"] == frames and all(untiled[k] == streamed[k] for k in keys)
print("untiled", untiled, "streamed", streamed, "frames", frames)
sys.exit(0 if ok else 1)
PY
# Measured (2026-12-02, seventh session, this seed): all 17 untiled planes >= 20 m^2 matched within
# 0.5 deg / 3 cm; one of them, a 37 m^2 sidewalk strip (x -9.6..-6.9, z -24.7..-7.2), comes out of
# its tile's own extraction as two planes (24 + 11 m^2, 0.9 cm apart) cut at z = -19 m, 6 m inside
# the tile (the tile's region growing stopped at a gap that the whole map's growth bridges); the
# merge joins only what a border cut (docs/map.md). Before the seventh session the same strip
# counted as unmatched (15 of 16). kitti07-like: 140 of 141, none split.
check "tiled = untiled (planes >= 20 m^2 within 0.5 deg / 3 cm, all matched, at most 1 split)" \
  python3 "$src/scripts/compare_plane_maps.py" "$tmp/untiled.json" "$tmp/tiled.json" \
  --allow-split 1
good() { python3 -c "import json; print(json.load(open('$1'))['stats']['gt_evaluation']['good'])"; }
# Measured: untiled 25, tiled 25 of the 25 GT planes (before the seventh session's robust fit: 22
# and 24; the untiled road plane took three sidewalk GT planes).
check "GT recall not lower tiled ($(good "$tmp/untiled.json") untiled vs $(good "$tmp/tiled.json"))" \
  test "$(good "$tmp/tiled.json")" -ge "$(good "$tmp/untiled.json")"

# MPI: two ranks on this machine, the same bytes as one process.
# `grep` without -q: under pipefail, `grep -q` exiting at the first match can end ldd with
# SIGPIPE, and the whole MPI half was then skipped as if MPI were missing.
if command -v mpirun >/dev/null 2>&1 && ldd "$planeloc" | grep libmpi >/dev/null; then
  root=()
  [ "$(id -u)" -eq 0 ] && root=(--allow-run-as-root)  # Open MPI refuses root without it
  run "$tmp/mpi.log" mpirun -n 2 --oversubscribe "${root[@]}" "$planeloc" map planes \
    --tiles "$tmp/tiles" --out "$tmp/mpi.json" --gt "$gt"
  check "mpirun -n 2 planes.json identical to one process" cmp "$tmp/tiled.json" "$tmp/mpi.json"
  check "both ranks processed tiles" \
    test "$(grep -c 'rank 1)' "$tmp/mpi.log")" -ge 1 -a "$(grep -c 'rank 0)' "$tmp/mpi.log")" -ge 1
elif [ "${PLANELOC_REQUIRE_COMPONENTS:-0}" = 1 ]; then
  check "mpirun -n 2 (planeloc built with MPI and mpirun installed; PLANELOC_REQUIRE_COMPONENTS=1)" false
else
  echo "skip mpirun (planeloc built without MPI or no mpirun)"
fi

# A broken tile: the run fails, names the tile, writes nothing.
broken="$(python3 -c "import json; print(json.load(open('$tmp/tiles/index.json'))['tiles'][1]['file'])")"
head -c 300 "$tmp/tiles/$broken" >"$tmp/cut" && mv "$tmp/cut" "$tmp/tiles/$broken"
"$planeloc" map planes --tiles "$tmp/tiles" --out "$tmp/broken.json" >"$tmp/broken.log" 2>&1
rc=$?
check "a broken tile: exit 2 (got $rc)" test "$rc" -eq 2
check "a broken tile: the message names it" grep -q "1 of $tiles tiles failed.*$broken" "$tmp/broken.log"
check "a broken tile: no planes.json" test ! -e "$tmp/broken.json"
exit $fail
