#!/usr/bin/env bash
# Same-run comparison with the real ORB-SLAM2 (issue 33 item 2): builds the peer when it is not
# built (scripts/peers/build_orbslam2.sh; a second call does nothing), then runs
# scripts/bench_peers.py, which writes BUILD/bench/peers.json; scripts/bench_report.py puts it in
# docs/benchmarks.md ("Same run as ORB-SLAM2"). Called by scripts/bench.sh unless --no-peers.
#
# Usage: scripts/bench_peers.sh [--out DIR] [--repeats N] [--drives "PRESET:SEED,... ..."]
#   defaults: BUILD/bench, 3 interleaved rounds, "small:3,11,21 kitti07-like:1,2", then the real
#   KITTI raw 0001 when ../shared/data has it (--real DIR, --no-real; ORB-SLAM2 and VO only)
# Never in CI: the peer takes minutes to build and the comparison 52 minutes on 2 cores (2026-12-06).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${PLANELOC_BUILD_DIR:-$root/build}"
case "${1:-}" in -h|--help) awk 'NR > 1 && !/^#/ {exit} NR > 1' "$0"; exit 0 ;; esac
"$root/scripts/peers/build_orbslam2.sh"
exec python3 "$root/scripts/bench_peers.py" --build "$build_dir" "$@"
