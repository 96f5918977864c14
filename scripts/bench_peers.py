#!/usr/bin/env python3
"""Same-run comparison with the real ORB-SLAM2 (issue 33 item 2): peers.json for docs/benchmarks.md.

Per drive (the bench's cached simulator drives, build/bench/data/<preset>-<seed>/, made by
scripts/bench_run.py's prepare_drive when missing), REPEATS rounds, each round running, one after
the other on the same machine:

  orbslam2       ORB-SLAM2 stereo without loop closing (build-peers/bin/orbslam2_stereo_kitti,
                 scripts/peers/build_orbslam2.sh; viewer off, no real-time wait; the vocabulary
                 build-peers/vocabulary/orbvoc.txt, self-trained: docs/peers.md)
  vo             planeloc run --no-planes (threaded, the default)
  planes-exact   planeloc run --planes, --init-sigma "0 0 0" (the exact start, no map lock)
  planes-prior   planeloc run --planes with the default prior "2 0.5 5" given the exact pose (the
                 path a user takes; the run registers itself to the map)
  planes-realtime  planes-exact with --realtime: frames arrive at the camera's rate (10 Hz) and
                 each frame's latency from arrival to pose is measured (p50 / p99 / max)

Interleaved rounds put the machine's load on every row alike. Per run: frames per second (frames /
the tracking loop's wall time, image decoding included, start-up and vocabulary loading not),
CPU ms per frame (user + system of the process over its frames, start-up included), frames
without a pose, ATE RMSE with no alignment and with SE(3) (`planeloc eval`), KITTI drift on paths
of 100 m or more, and peak RSS (ru_maxrss). ORB-SLAM2's poses are in the frame of its first
camera; for "no alignment" they are put into the GT frame by the first GT pose
(T_gt0 * T_est_i), as planeloc's runs start from that same pose. ORB-SLAM2's poses are those of
each frame as it was tracked (its file, written frame by frame like planeloc's); its end-of-run
keyframe trajectory (SaveTrajectoryKITTI) is evaluated too, as `ate_final_*`.

Then the real KITTI raw drive 0001 (108 frames; $PLANELOC_SHARED_DATA or ../shared/data), put into
the odometry layout by scripts/peers/kitti_raw_as_odometry.py (links, no copies) so that both
programs read the same files: ORB-SLAM2 and planeloc VO only, for speed and tracking (it has no
ground truth and no LiDAR map).

Usage: scripts/bench_peers.py [--build build] [--out BUILD/bench] [--repeats 3]
                              [--drives "small:3,11,21 kitti07-like:1,2"] [--real RAW | --no-real]
"""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_run  # noqa: E402  (the bench's drive cache, process measurement and evaluation)
from bench_run import ROOT, BenchError, command_text, now_utc, rel, run_measured  # noqa: E402

PEERS = os.path.join(ROOT, "build-peers")
RUNNER = os.path.join(PEERS, "bin", "orbslam2_stereo_kitti")
VOCABULARY = os.path.join(PEERS, "vocabulary", "orbvoc.txt")
STAMP = os.path.join(PEERS, ".orbslam2.stamp")
DEFAULT_DRIVES = [("small", [3, 11, 21]), ("kitti07-like", [1, 2])]
ROWS = ["orbslam2", "vo", "planes-exact", "planes-prior", "planes-realtime"]
# The real drive: no ground truth and no LiDAR map (../shared/data/README.md), so speed and
# tracking of ORB-SLAM2 and planeloc VO only.
SHARED_DATA = os.environ.get("PLANELOC_SHARED_DATA",
                             os.path.join(os.path.dirname(ROOT), "shared", "data"))
REAL_DRIVE = os.path.join(SHARED_DATA, "kitti-raw-2011_09_26_drive_0001")
REAL_ROWS = ["orbslam2", "vo"]


def read_kitti(path):
    poses = []
    with open(path) as f:
        for line in f:
            values = [float(v) for v in line.split()]
            if len(values) == 12:
                poses.append(values)
    return poses


def compose(a, b):
    """3x4 row-major poses a * b."""
    out = []
    for r in range(3):
        for c in range(4):
            v = sum(a[4 * r + k] * b[4 * k + c] for k in range(3))
            if c == 3:
                v += a[4 * r + 3]
            out.append(v)
    return out


def into_gt_frame(est_path, gt_path, out_path):
    """The estimate's poses left-multiplied by the first GT pose."""
    first = read_kitti(gt_path)[0]
    with open(out_path, "w") as f:
        for pose in read_kitti(est_path):
            f.write(" ".join(f"{v:.9e}" for v in compose(first, pose)) + "\n")


def evaluate(planeloc, gt, est, prefix, kitti):
    result = {}
    for align in ("none", "se3"):
        json_path = f"{prefix}.eval-{align}.json"
        cmd = [planeloc, "eval", "--gt", gt, "--est", est, "--align", align, "--json", json_path]
        if kitti and align == "none":
            cmd.append("--kitti-drift")
        run_measured(cmd, f"{prefix}.eval-{align}.log")
        with open(json_path) as f:
            stats = json.load(f)
        result[f"ate_{align}_m"] = stats["ape"]["rmse"]
        if "kitti_drift" in stats:
            result["t_rel_percent"] = stats["kitti_drift"]["t_rel_percent"]
            result["r_rel_deg_per_100m"] = stats["kitti_drift"]["r_rel_deg_per_100m"]
    return result


def run_orbslam2(planeloc, drive, seq, gt, out_prefix, settings):
    """`gt` None: a real drive without ground truth (speed and tracking only)."""
    est = out_prefix + ".txt"
    cmd = [RUNNER, VOCABULARY, settings, seq, est]
    record = {"command": command_text(cmd)}
    try:
        record.update(run_measured(cmd, out_prefix + ".log"))
        record["exit"] = 0
    except BenchError as e:  # a crash or total loss is a row that says so
        record.update({"exit": str(e), "frames": drive["frames"], "tracked": 0})
        return record
    rows = []
    with open(est + ".timing.csv") as f:
        header = f.readline().strip().split(",")
        for line in f:
            rows.append(dict(zip(header, line.strip().split(","))))
    loop_s = sum(float(r["decode_ms"]) + float(r["track_ms"]) for r in rows) / 1000.0
    tracked = sum(1 for r in rows if r["pose_valid"] == "1")
    record.update({"frames": len(rows), "tracked": tracked, "lost": len(rows) - tracked,
                   "map_resets": max((int(r["map_id"]) for r in rows), default=0),
                   "loop_s": loop_s, "fps": len(rows) / max(loop_s, 1e-9),
                   "median_track_ms": statistics.median(float(r["track_ms"]) for r in rows)})
    if gt is None:
        return record
    in_gt = out_prefix + ".gtframe.txt"
    into_gt_frame(est, gt, in_gt)
    kitti = drive["path_m"] >= bench_run.KITTI_MIN_PATH_M
    ate = evaluate(planeloc, gt, in_gt, out_prefix, kitti)
    record.update(ate)
    final = est + ".final.txt"
    if os.path.exists(final) and len(read_kitti(final)) == len(rows):
        final_gt = out_prefix + ".final.gtframe.txt"
        into_gt_frame(final, gt, final_gt)
        final_ate = evaluate(planeloc, gt, final_gt, out_prefix + ".final", False)
        record["ate_final_none_m"] = final_ate["ate_none_m"]
        record["ate_final_se3_m"] = final_ate["ate_se3_m"]
    return record


def run_planeloc(planeloc, drive, seq, gt, planes, out_prefix, row):
    """`gt` None: a real drive, started at the identity, without evaluation."""
    cmd = [planeloc, "run", "--sequence", seq] + (["--init-pose-from", gt] if gt else [])
    if row == "vo":
        cmd.append("--no-planes")
    else:
        cmd += ["--planes", planes]
        if row in ("planes-exact", "planes-realtime"):
            cmd += ["--init-sigma", "0 0 0"]
        if row == "planes-realtime":
            cmd.append("--realtime")
    cmd += ["--out", out_prefix + ".txt", "--stats", out_prefix + ".jsonl"]
    record = {}
    try:
        record.update(run_measured(cmd, out_prefix + ".log"))
        record["exit"] = 0
    except BenchError as e:
        record.update({"exit": str(e), "command": command_text(cmd)})
        return record
    with open(out_prefix + ".jsonl.summary.json") as f:
        summary = json.load(f)
    record.update({"frames": summary["frames"], "tracked": summary["frames"] - summary["lost"],
                   "lost": summary["lost"], "loop_s": summary["seconds"],
                   "fps": summary["frames"] / max(summary["seconds"], 1e-9)})
    for key, value in summary.get("latency_ms", {}).items():
        record[f"latency_{key}_ms"] = value
    if gt is None:
        return record
    kitti = drive["path_m"] >= bench_run.KITTI_MIN_PATH_M
    record.update(evaluate(planeloc, gt, out_prefix + ".txt", out_prefix, kitti))
    return record


def summarize(runs):
    """Median and range of each numeric field over the repeats that ran."""
    ok = [r for r in runs if r.get("exit") == 0]
    out = {"repeats": len(runs), "completed": len(ok),
           "failures": [r["exit"] for r in runs if r.get("exit") != 0]}
    fields = ["fps", "ate_none_m", "ate_se3_m", "t_rel_percent", "r_rel_deg_per_100m",
              "peak_rss_mb", "lost", "ate_final_none_m", "ate_final_se3_m", "median_track_ms",
              "latency_p50_ms", "latency_p99_ms", "latency_max_ms"]
    for field in fields:
        values = [r[field] for r in ok if field in r]
        if values:
            out[field] = {"median": statistics.median(values), "min": min(values),
                          "max": max(values)}
    cpu = [(r["user_cpu_s"] + r["system_cpu_s"]) * 1000.0 / r["frames"] for r in ok
           if "user_cpu_s" in r and r.get("frames")]
    if cpu:
        out["cpu_ms_per_frame"] = {"median": statistics.median(cpu), "min": min(cpu),
                                   "max": max(cpu)}
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.environ.get("PLANELOC_BUILD_DIR",
                                                          os.path.join(ROOT, "build")))
    parser.add_argument("--out", help="results folder (default: BUILD/bench)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--drives", type=bench_run.parse_drives, default=DEFAULT_DRIVES)
    parser.add_argument("--real", default=REAL_DRIVE,
                        help="a KITTI raw drive (synced, rectified) run for speed and tracking "
                             "only, ORB-SLAM2 and planeloc VO (default: the shared data's 0001 "
                             "when it is there)")
    parser.add_argument("--no-real", action="store_true", help="without the real drive")
    args = parser.parse_args()
    out = args.out or os.path.join(args.build, "bench")
    planeloc = os.path.join(args.build, "bin", "planeloc")
    missing = [p for p in (STAMP, RUNNER, VOCABULARY) if not os.path.exists(p)]
    if missing:
        print(f"bench_peers.py: the ORB-SLAM2 peer is not built ({rel(missing[0])} missing): run "
              "scripts/peers/build_orbslam2.sh first", file=sys.stderr)
        return 2
    if not os.path.exists(planeloc):
        print(f"bench_peers.py: {rel(planeloc)} missing: build planeloc first", file=sys.stderr)
        return 2
    data_dir = os.path.join(out, "data")
    runs_root = os.path.join(out, "peers")
    os.makedirs(runs_root, exist_ok=True)
    result = {"date_start": now_utc(), "commit": bench_run.git("rev-parse", "--short=7", "HEAD"),
              "load_start": os.getloadavg(), "repeats": args.repeats,
              "vocabulary": rel(VOCABULARY), "runner": rel(RUNNER), "drives": []}
    def compare(preset, seed, seq, gt, planes, rows, drive):
        runs_dir = os.path.join(runs_root, f"{preset}-{seed}".replace(" ", "-"))
        os.makedirs(runs_dir, exist_ok=True)
        settings = os.path.join(runs_dir, "orbslam2.yaml")
        run_measured([sys.executable, os.path.join(ROOT, "scripts", "peers",
                                                   "orbslam2_settings.py"), seq, "-o", settings],
                     os.path.join(runs_dir, "settings.log"))
        runs = {row: [] for row in rows}
        for repeat in range(args.repeats):
            for row in rows:
                print(f"--- peers {preset} {seed}: {row}, round {repeat + 1}", flush=True)
                prefix = os.path.join(runs_dir, f"{row}.{repeat}")
                if row == "orbslam2":
                    record = run_orbslam2(planeloc, drive, seq, gt, prefix, settings)
                else:
                    record = run_planeloc(planeloc, drive, seq, gt, planes, prefix, row)
                runs[row].append(record)
        result["drives"].append({
            "preset": preset, "seed": seed, "frames": drive["frames"], "path_m": drive["path_m"],
            "ground_truth": gt is not None, "runs": runs,
            "summary": {row: summarize(runs[row]) for row in rows}})
        with open(os.path.join(out, "peers.json"), "w") as f:  # resumable reading
            json.dump(result, f, indent=1)

    try:
        for preset, seeds in args.drives:
            for seed in seeds:
                drive = bench_run.prepare_drive(planeloc, data_dir, preset, seed, False)
                data = os.path.join(ROOT, drive["dir"])
                compare(preset, seed, os.path.join(data, "sim", "sequences", "00"),
                        os.path.join(data, "sim", "poses", "00.txt"),
                        os.path.join(data, "planes.json"), ROWS, drive)
        if not args.no_real and args.real and os.path.isdir(args.real):
            name = os.path.basename(os.path.normpath(args.real))
            seq = os.path.join(data_dir, name, "sequences", "00")
            run_measured([sys.executable, os.path.join(ROOT, "scripts", "peers",
                                                       "kitti_raw_as_odometry.py"), args.real, seq],
                         os.path.join(data_dir, name + ".log"))
            with open(os.path.join(seq, "times.txt")) as f:
                frames = sum(1 for line in f if line.strip())
            compare("KITTI raw", name.replace("kitti-raw-", ""), seq, None, None, REAL_ROWS,
                    {"frames": frames, "path_m": None})
        elif not args.no_real:
            print(f"bench_peers.py: no real drive ({rel(args.real)} missing): skipped",
                  flush=True)
    except BenchError as e:
        print(f"bench_peers.py: {e}", file=sys.stderr)
        return 1
    result["date_end"] = now_utc()
    result["load_end"] = os.getloadavg()
    with open(os.path.join(out, "peers.json"), "w") as f:
        json.dump(result, f, indent=1)
    print(f"wrote {rel(os.path.join(out, 'peers.json'))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
