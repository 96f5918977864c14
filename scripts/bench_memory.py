#!/usr/bin/env python3
"""Peak RSS of `planeloc run` against distance driven, map maintenance on vs off (issue 11 item 7).

A benchmark, not a test. Simulates a long drive along a KITTI ground-truth path (`planeloc sim
--trajectory`), then tracks it (visual odometry, --deterministic) once with the default settings
(keyframe culling, point fusion, forgetting old keyframes) and once with all three off. While a run
goes, the script samples /proc/<pid>/status (VmRSS, VmHWM) every --interval seconds together with
the number of lines of the run's --stats file (one flushed line per frame), so each sample has a
frame and thus a distance along the ground truth. Writes build/bench/memory.json (or --out) with the
samples and, per run, the peak RSS when each checkpoint distance was first reached.

Usage: scripts/bench_memory.py [--build build] [--trajectory ../shared/data/kitti-odometry-gt/poses/00.txt]
                               [--frames 3000] [--run-frames N] [--sim EXISTING_SIM_DIR]
                               [--work build/bench/memory_sim] [--out build/bench/memory.json]
                               [--off-settings keep|all] [--sequential]
                               [--planes PLANES_JSON [--init-sigma "0 0 0"]]
The path must be nearly planar: the simulator fits one ground plane to it (docs/sim.md), so a hilly
drive (KITTI 02, 08, 09) puts the camera under the road; KITTI 00 stays within 1.4 m of its plane.
"""
import argparse
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

OFF_SETTINGS = """%YAML:1.0
Mapping.cullKeyframes: 0
Mapping.fusePoints: 0
Mapping.keepKeyframes: 0
"""

# Only forgetting off (culling and fusion as by default): the linear-growth
# reference for the defaults.
KEEP_ALL_SETTINGS = """%YAML:1.0
Mapping.keepKeyframes: 0
"""


def cumulative_distance(poses_path):
    dist, last, out = 0.0, None, []
    with open(poses_path) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            if len(v) != 12:
                continue
            p = (v[3], v[7], v[11])
            if last is not None:
                dist += math.dist(p, last)
            last = p
            out.append(dist)
    return out


def status_kb(pid):
    values = {}
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                key, _, rest = line.partition(":")
                if key in ("VmRSS", "VmHWM"):
                    values[key] = int(rest.split()[0])
    except OSError:
        return None
    return values


def count_lines(path):
    try:
        with open(path, "rb") as f:
            return sum(1 for _ in f)
    except OSError:
        return 0


def run_all(planeloc, seq, poses, work, configs, interval, distance, sequential=False,
            mode=("--no-planes",)):
    """Runs the configurations side by side (on a shared machine each process gets its own share
    of the CPU; RSS is per process), or one after another with `sequential`, and samples each
    one's RSS with its frame count."""
    if sequential:
        runs = {}
        for config in configs:
            runs.update(run_all(planeloc, seq, poses, work, (config,), interval, distance,
                                mode=mode))
        return runs
    runs = {}
    for name, settings in configs:
        traj = os.path.join(work, f"traj_{name}.txt")
        stats = os.path.join(work, f"stats_{name}.jsonl")
        cmd = [planeloc, "run", "--sequence", seq, "--init-pose-from", poses, *mode,
               "--out", traj, "--stats", stats, "--deterministic"]
        if settings:
            cmd += ["--config", settings]
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        runs[name] = {"command": " ".join(cmd), "proc": proc, "stats": stats, "trajectory": traj,
                      "samples": [], "start": time.time()}
    while any(r["proc"].poll() is None for r in runs.values()):
        for r in runs.values():
            if r["proc"].poll() is not None:
                if "seconds" not in r:
                    r["seconds"] = round(time.time() - r["start"], 1)
                continue
            s = status_kb(r["proc"].pid)
            frames = count_lines(r["stats"])
            if s and "VmRSS" in s:
                d = distance[min(frames, len(distance)) - 1] if frames > 0 else 0.0
                r["samples"].append({"t": round(time.time() - r["start"], 2), "frames": frames,
                                     "distance_m": round(d, 1),
                                     "rss_mb": round(s["VmRSS"] / 1024, 1),
                                     "hwm_mb": round(s.get("VmHWM", 0) / 1024, 1)})
        time.sleep(interval)
    for name, r in runs.items():
        proc = r.pop("proc")
        r.setdefault("seconds", round(time.time() - r.pop("start"), 1))
        r.pop("start", None)
        if proc.returncode != 0:
            sys.exit(f"bench_memory: {r['command']} failed ({proc.returncode})")
        try:
            with open(r["stats"] + ".summary.json") as f:
                r["summary"] = json.load(f)
        except OSError:
            r["summary"] = {}
    return runs


def checkpoints(samples, distances):
    rows = []
    for d in distances:
        hit = next((s for s in samples if s["distance_m"] >= d), None)
        if hit:
            rows.append({"distance_m": d, "frames": hit["frames"], "peak_rss_mb": hit["hwm_mb"],
                         "rss_mb": hit["rss_mb"]})
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--planeloc", default=None, help="binary (default BUILD/bin/planeloc)")
    ap.add_argument("--trajectory", default=os.path.join(
        ROOT, "..", "shared", "data", "kitti-odometry-gt", "poses", "00.txt"))
    ap.add_argument("--frames", type=int, default=3000)
    ap.add_argument("--preset", default="kitti07-like")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--work", default=None, help="sim + run outputs (default build/bench/memory_sim)")
    ap.add_argument("--out", default=None, help="JSON results (default build/bench/memory.json)")
    ap.add_argument("--sim", default=None,
                    help="an existing `planeloc sim` output folder to drive instead of simulating")
    ap.add_argument("--run-frames", type=int, default=0,
                    help="track only the first N frames (0: all; the sim writes poses first, so a "
                    "run can start on the frames rendered so far)")
    ap.add_argument("--interval", type=float, default=0.5, help="seconds between RSS samples")
    ap.add_argument("--checkpoints", default="250,500,1000,2000,3000,4000",
                    help="distances (m) reported in the table")
    ap.add_argument("--off-settings", choices=("all", "keep"), default="all",
                    help="the 'off' run: culling, fusion and forgetting off (all) or only "
                    "forgetting off, Mapping.keepKeyframes: 0 (keep)")
    ap.add_argument("--planes", default=None,
                    help="plane map (planes.json) to localize in instead of visual odometry")
    ap.add_argument("--init-sigma", default=None, help="with --planes: run's --init-sigma")
    ap.add_argument("--sequential", action="store_true",
                    help="run 'on' then 'off' instead of side by side (one heavy job at a time)")
    args = ap.parse_args()
    planeloc = args.planeloc or os.path.join(args.build, "bin", "planeloc")
    work = args.work or os.path.join(args.build, "bench", "memory_sim")
    out = args.out or os.path.join(args.build, "bench", "memory.json")
    os.makedirs(work, exist_ok=True)
    os.makedirs(os.path.dirname(out), exist_ok=True)

    sim = args.sim or os.path.join(work, "sim")
    poses = os.path.join(sim, "poses", "00.txt")
    seq = os.path.join(sim, "sequences", "00")
    if not args.sim and not (os.path.exists(poses) and
                             len(cumulative_distance(poses)) >= args.frames):
        subprocess.run([planeloc, "sim", "--out", sim, "--preset", args.preset, "--seed",
                        str(args.seed), "--frames", str(args.frames), "--trajectory",
                        args.trajectory, "--force"], check=True)
    if args.run_frames:
        # The first N frames as a sequence of their own (symlinks): the sim writes all poses and
        # times first, so a run can start on the frames rendered so far.
        view = os.path.join(work, f"first_{args.run_frames}")
        subprocess.run(["rm", "-rf", view], check=True)
        for sub in ("image_0", "image_1"):
            os.makedirs(os.path.join(view, "sequences", "00", sub))
            for i in range(args.run_frames):
                name = f"{i:06d}.png"
                os.symlink(os.path.join(seq, sub, name), os.path.join(view, "sequences", "00", sub, name))
        os.makedirs(os.path.join(view, "poses"))
        for src, dst in ((os.path.join(seq, "times.txt"), os.path.join(view, "sequences", "00", "times.txt")),
                         (poses, os.path.join(view, "poses", "00.txt"))):
            with open(src) as f, open(dst, "w") as g:
                g.writelines(f.readlines()[:args.run_frames])
        with open(os.path.join(seq, "calib.txt")) as f, \
                open(os.path.join(view, "sequences", "00", "calib.txt"), "w") as g:
            g.write(f.read())
        seq = os.path.join(view, "sequences", "00")
        poses = os.path.join(view, "poses", "00.txt")
    distance = cumulative_distance(poses)
    off = os.path.join(work, "maintenance_off.yaml")
    with open(off, "w") as f:
        f.write(OFF_SETTINGS if args.off_settings == "all" else KEEP_ALL_SETTINGS)

    wanted = [float(x) for x in args.checkpoints.split(",")]
    runs = run_all(planeloc, seq, poses, work, (("on", None), ("off", off)), args.interval,
                   distance, args.sequential,
                   ("--planes", args.planes, *(("--init-sigma", args.init_sigma)
                                               if args.init_sigma else ()))
                   if args.planes else ("--no-planes",))
    for name, r in runs.items():
        r["checkpoints"] = checkpoints(r["samples"], wanted)
        for align in ("se3", "none"):
            ate = os.path.join(work, f"ate_{name}_{align}.json")
            subprocess.run([planeloc, "eval", "--gt", poses, "--est", r["trajectory"], "--align",
                            align, "--json", ate], check=True, stdout=subprocess.DEVNULL)
            with open(ate) as f:
                r[f"eval_{align}"] = json.load(f)

    def git(*a):
        return subprocess.run(["git", "-C", ROOT, *a], capture_output=True, text=True).stdout.strip()

    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), platform.processor())
    result = {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
              "commit": git("rev-parse", "--short", "HEAD"), "dirty": bool(git("status", "--porcelain")),
              "cpu": cpu, "cores": os.cpu_count(), "loadavg": os.getloadavg(),
              "trajectory": os.path.abspath(args.trajectory), "frames": args.frames,
              "run_frames": args.run_frames or args.frames, "off_settings": args.off_settings,
              "planes": args.planes, "init_sigma": args.init_sigma,
              "sequential": args.sequential,
              "path_m": round(distance[-1], 1), "sim": os.path.abspath(sim), "preset": args.preset, "seed": args.seed,
              "runs": runs}
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
    print(f"{'distance m':>10} {'on: peak RSS MB':>16} {'off: peak RSS MB':>17}")
    for row_on in runs["on"]["checkpoints"]:
        row_off = next((r for r in runs["off"]["checkpoints"]
                        if r["distance_m"] == row_on["distance_m"]), None)
        print(f"{row_on['distance_m']:>10.0f} {row_on['peak_rss_mb']:>16.1f} "
              f"{(row_off or {}).get('peak_rss_mb', float('nan')):>17.1f}")
    for name in runs:
        print(f"{name}: final peak {runs[name]['samples'][-1]['hwm_mb']} MB, "
              f"{runs[name]['seconds']} s, ATE RMSE none {runs[name]['eval_none']['ape']['rmse']:.3f} m "
              f"se3 {runs[name]['eval_se3']['ape']['rmse']:.3f} m, "
              f"summary {json.dumps(runs[name]['summary'].get('local_ba'))}")
    print(f"bench_memory: wrote {out}")


if __name__ == "__main__":
    main()
