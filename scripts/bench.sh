#!/usr/bin/env bash
# Builds Release, runs every benchmark and rewrites docs/benchmarks.md (issue 12 item 4).
#
# Usage: scripts/bench.sh [--quick] [--fresh] [--no-build] [--drives "PRESET:SEED,... ..."]
#                         [--no-robustness] [--no-map-lock] [--no-peers] [--no-room]
#                         [--no-mutants] [--no-prior-modes]
#   --quick     under 5 minutes on a 2-core machine: the simulator's `tiny` drive (one seed) and a
#               subset of the Google Benchmark programs with short minimum times
#   (default)   every benchmark; `small` seeds 3, 11, 21 and `kitti07-like` seeds 1, 2 (about an
#               hour, most of it kitti07-like's simulation and plane map, cached for later runs);
#               and issue 10's table of wrong plane maps and the ablation (33 minutes on 2
#               cores when its drives and maps are made first, 2026-12-03)
#               and issue 30's default start (the default prior from the exact start on tiny, small
#               and kitti07-like drives, 20 draws from it on small 3, 11, 21)
#   --no-robustness  the full mode without the wrong maps and the ablation
#   --no-map-lock    the full mode without issue 30's default-start runs
#   --no-peers  the full mode without issue 33's same-run comparison with the real ORB-SLAM2
#               (scripts/bench_peers.sh: builds the peer once, then about 25 minutes)
#               and issue 36's frame rate with and without the live view (scripts/bench_live_view.py,
#               about 6 minutes)
#   --no-room   the full mode without issue 35's indoor benchmark (scripts/bench_room.py: the
#               room preset, seeds 1, 2, 3; about 35 minutes when its drives must be simulated,
#               about 13 when they are cached in build/bench/data/room/)
#   --no-mutants  the full mode without issue 37's mutation checks (scripts/mutants.sh
#               --update-doc: each key mechanism broken in turn in a worktree of its own, the
#               table in docs/reliability.md; about 60 minutes on 2 cores, most of it builds)
#   --no-prior-modes  the full mode without issue 34's same-run comparison of the prior modes
#               (scripts/bench_prior_modes.py: small 3/11/21, rural 1/2/3, small 7 with changing
#               lighting and kitti07-like 1/2; about 70 minutes when its drives must be made)
#   --fresh     remake the cached simulator drives and plane maps (build/bench/data/)
#   --no-build  use the binaries in the build folder as they are
#   --drives    other simulated drives than the mode's, e.g. "small:3 kitti07-like:1" (the page
#               says so)
# One section alone, spliced into the page as it is (each row says its own run): issue 30's
#   `scripts/bench_run.py --only-map-lock [tiny,small] --out DIR` then
#   `scripts/bench_report_map_lock.py --results DIR`; issue 35's `scripts/bench_room.py --out
#   DIR/room.json` then `scripts/bench_report_room.py --results DIR`; issue 34's likewise.
# Results: JSON in build/bench/ (scripts/bench_run.py), then docs/benchmarks.md written from them
# by scripts/bench_report.py. Never edit a number of docs/benchmarks.md by hand: rerun this. On a
# shared machine, run it under `nice -n 10`. PLANELOC_BUILD_DIR picks another build folder.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${PLANELOC_BUILD_DIR:-$root/build}"
run_args=()
build=1
peers=1
mutants=1
live_view=1
room=1
prior_modes=1
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) run_args+=(--quick); peers=0; mutants=0; live_view=0; room=0; prior_modes=0; shift ;;
    --no-peers) peers=0; shift ;;
    --no-room) room=0; shift ;;
    --no-prior-modes) prior_modes=0; shift ;;
    --no-mutants) mutants=0; shift ;;
    --fresh) run_args+=(--fresh); shift ;;
    --no-build) build=0; shift ;;
    --drives) run_args+=(--drives "$2"); shift 2 ;;
    --no-robustness) run_args+=(--no-robustness); shift ;;
    --no-map-lock) run_args+=(--no-map-lock); shift ;;
    -h|--help) awk 'NR > 1 && !/^#/ {exit} NR > 1' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
start=$(date +%s)
if [ "$build" = 1 ]; then
  "$root/scripts/setup.sh"
  PLANELOC_BUILD_DIR="$build_dir" "$root/scripts/build.sh"
fi
# A comparison from an earlier run never reaches this run's page.
rm -f "$build_dir/bench/peers.json" "$build_dir/bench/live_view.json" "$build_dir/bench/room.json" \
  "$build_dir/bench/prior_modes.json"
python3 "$root/scripts/bench_run.py" --build "$build_dir" --out "$build_dir/bench" "${run_args[@]}"
if [ "$live_view" = 1 ]; then
  # Issue 36: fps with and without the live view (about 6 minutes).
  python3 "$root/scripts/bench_live_view.py" --build "$build_dir" --out "$build_dir/bench"
fi
if [ "$room" = 1 ]; then
  # Issue 35: the room preset (about 35 minutes with its simulation, 13 when cached).
  python3 "$root/scripts/bench_room.py" --build "$build_dir" --out "$build_dir/bench/room.json"
fi
if [ "$prior_modes" = 1 ]; then
  # Issue 34: VO, planes, Kim et al., depth and hybrid on the same drives (about 70 minutes).
  python3 "$root/scripts/bench_prior_modes.py" --build "$build_dir"
fi
if [ "$peers" = 1 ]; then
  PLANELOC_BUILD_DIR="$build_dir" "$root/scripts/bench_peers.sh" --out "$build_dir/bench"
fi
python3 "$root/scripts/bench_report.py" --results "$build_dir/bench" \
  --out "$root/docs/benchmarks.md"
if [ "$mutants" = 1 ]; then
  # A surviving mutant is a finding, not a broken bench: the table says which; the page above is
  # already written.
  "$root/scripts/mutants.sh" --update-doc || echo "bench.sh: a mutant survived or did not build \
(docs/reliability.md, 'Mutation checks')" >&2
fi
echo "bench.sh: $(($(date +%s) - start)) s in all (build included)"
