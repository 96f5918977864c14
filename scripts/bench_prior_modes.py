#!/usr/bin/env python3
"""Issue 34 item 4: the same-run comparison of the prior modes. On each drive, in one session and
on the same frames: visual odometry, plane mode, Kim et al. (the depth-to-map residual in each
frame's pose only), depth mode and hybrid mode. Writes prior_modes.json (build/bench by default).

Drives (prepared and cached as scripts/bench_run.py's, under build/bench/data/): `small` seeds 3,
11, 21, `rural` seeds 1, 2, 3, `small` seed 7 with `--lighting changing` and, unless --no-long,
`kitti07-like` seeds 1, 2. Every run from the first ground-truth pose (plane and hybrid with
`--init-sigma "0 0 0"`), threaded as a user runs it:

  vo      --no-planes
  plane   --planes planes.json
  kim     --map-cloud map.pcd with DepthPrior.windowSurfaces 0 (the paper's residual alone)
  depth   --map-cloud map.pcd
  hybrid  --planes planes.json --map-cloud map.pcd

Per run: ATE RMSE with no alignment and KITTI t_rel from `planeloc eval`, frames per second of the
tracking loop (the run's summary), CPU ms per frame (user + system time of the process over its
frames) and peak RSS (ru_maxrss of wait4(2)); per drive the map's size on disk (planes.json and the
map cloud, map.pcd at 0.1 m). scripts/bench_report_prior_modes.py renders the section of
docs/benchmarks.md.

Usage: scripts/bench_prior_modes.py [--build build] [--out build/bench/prior_modes.json]
                                    [--drives "small:3,11,21 rural:1,2,3"] [--no-long] [--resume]
--resume keeps the drives the existing output already has without an error (an interrupted or
--no-long run is completed by the drives it lacks); the page's date and commit are then the new
run's, and the results of the kept drives say theirs.
On 2 cores: about 30 minutes without the kitti07-like drives when the drives must be made, 20
when they are cached; the two kitti07-like drives add about 40.
"""
import argparse
import datetime
import json
import os
import sys

from bench_run import (BenchError, ROOT, cpu_model, evaluate, parse_drives, prepare_drive, rel,
                       run_measured, tree_commit)

DRIVES = [("small", [3, 11, 21]), ("rural", [1, 2, 3])]
LIGHTING_DRIVE = ("small", 7, "changing")
LONG_DRIVES = [("kitti07-like", [1, 2])]
MODES = ["vo", "plane", "kim", "depth", "hybrid"]
KIM_SETTINGS = "%YAML:1.0\nDepthPrior.windowSurfaces: 0\n"


def mode_args(mode, data, settings_dir):
    planes = ["--planes", os.path.join(data, "planes.json"), "--init-sigma", "0 0 0"]
    cloud = ["--map-cloud", os.path.join(data, "map.pcd")]
    if mode == "vo":
        return ["--no-planes"]
    if mode == "plane":
        return planes
    if mode == "kim":
        return cloud + ["--config", os.path.join(settings_dir, "kim.yaml")]
    if mode == "depth":
        return cloud
    return planes + cloud


def run_mode(planeloc, drive, mode, runs_dir):
    data = os.path.join(ROOT, drive["dir"])
    poses = os.path.join(data, "sim", "poses", "00.txt")
    prefix = os.path.join(runs_dir, mode)
    cmd = [planeloc, "run", "--sequence", os.path.join(data, "sim", "sequences", "00"),
           "--init-pose-from", poses, *mode_args(mode, data, runs_dir),
           "--out", prefix + ".txt", "--stats", prefix + ".jsonl"]
    record = {"mode": mode}
    try:
        record.update(run_measured(cmd, prefix + ".log"))
        with open(prefix + ".jsonl.summary.json") as f:
            summary = json.load(f)
        frames = summary["frames"]
        cpu_s = record["user_cpu_s"] + record["system_cpu_s"]
        record.update({"frames": frames, "lost": summary["lost"],
                       "fps": frames / max(summary["seconds"], 1e-9),
                       "cpu_ms_per_frame": 1000.0 * cpu_s / max(frames, 1),
                       "mean_ba_plane_residuals": summary.get("mean_ba_plane_residuals")})
        record.update(evaluate(planeloc, poses, prefix + ".txt", prefix, drive["path_m"] >= 100))
    except (BenchError, OSError, ValueError, KeyError) as e:
        record["error"] = str(e)
    return record


def one_drive(planeloc, data_dir, out_dir, preset, seed, lighting):
    drive = prepare_drive(planeloc, data_dir, preset, seed, False, lighting)
    name = os.path.basename(drive["dir"])
    runs_dir = os.path.join(out_dir, "runs", "prior-modes", name)
    os.makedirs(runs_dir, exist_ok=True)
    with open(os.path.join(runs_dir, "kim.yaml"), "w") as f:
        f.write(KIM_SETTINGS)
    data = os.path.join(ROOT, drive["dir"])
    result = {"preset": preset, "seed": seed, "lighting": lighting or "constant",
              "frames": drive["frames"], "path_m": drive["path_m"],
              "planes_json_mb": os.path.getsize(os.path.join(data, "planes.json")) / 1e6,
              "map_cloud_mb": os.path.getsize(os.path.join(data, "map.pcd")) / 1e6, "runs": {}}
    for mode in MODES:
        print(f"--- {name}: {mode}", flush=True)
        record = run_mode(planeloc, drive, mode, runs_dir)
        result["runs"][mode] = record
        ate = record.get("ate3d_m")
        print(f"    ATE {ate if ate is None else round(ate, 3)} m, "
              f"{record.get('fps', 0):.1f} fps" + (f", {record['error']}" if "error" in record
                                                   else ""), flush=True)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--out", default=None)
    parser.add_argument("--drives", type=parse_drives, default=None,
                        help="replaces the constant-lighting drives, e.g. 'rural:1,2'")
    parser.add_argument("--no-long", action="store_true", help="without the kitti07-like drives")
    parser.add_argument("--resume", action="store_true",
                        help="keep the drives the existing output has without an error")
    args = parser.parse_args()
    out_dir = os.path.join(args.build, "bench")
    out = args.out or os.path.join(out_dir, "prior_modes.json")
    planeloc = os.path.join(args.build, "bin", "planeloc")
    data_dir = os.path.join(out_dir, "data")
    plan = [(p, s, None) for p, seeds in (args.drives or DRIVES) for s in seeds]
    plan.append(LIGHTING_DRIVE)
    if not args.no_long and args.drives is None:
        plan += [(p, s, None) for p, seeds in LONG_DRIVES for s in seeds]
    kept = {}
    if args.resume and os.path.exists(out):
        with open(out) as f:
            previous = json.load(f)
        for d in previous.get("drives", []):
            if "error" not in d:
                d.setdefault("measured", {"date": previous.get("date"),
                                          "commit": previous.get("commit")})
                kept[(d["preset"], d["seed"], d["lighting"])] = d
    drives = []
    for preset, seed, lighting in plan:
        if (preset, seed, lighting or "constant") in kept:
            print(f"--- {preset} seed {seed}: kept from {rel(out)}", flush=True)
            drives.append(kept[(preset, seed, lighting or "constant")])
            continue
        try:
            drives.append(one_drive(planeloc, data_dir, out_dir, preset, seed, lighting))
        except (BenchError, OSError, ValueError, KeyError) as e:  # no drive or no map
            print(f"{preset} {seed}: {e}", file=sys.stderr)
            drives.append({"preset": preset, "seed": seed, "lighting": lighting or "constant",
                           "error": str(e)})
    result = {"date": datetime.date.today().isoformat(), "commit": tree_commit("-dirty"),
              "cpu": cpu_model(), "cpus": os.cpu_count(),
              "command": "scripts/bench_prior_modes.py" + (" --no-long" if args.no_long else "")
              + ("" if args.drives is None else " --drives ...")
              + (f" --resume ({len(kept)} drives kept)" if args.resume else ""),
              "drives": drives}
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
    print(f"wrote {rel(out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
