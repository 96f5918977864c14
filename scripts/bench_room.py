#!/usr/bin/env python3
"""Issue 35's acceptance benchmark on the indoor `room` preset: visual odometry, plane mode from
the exact start and from coarse starts, per seed. Writes room.json (build/bench by default).

Per seed, in WORK/room_s<SEED> (made once, reused while its world/README.txt has the same seed and
frames): `planeloc sim --preset room`, the survey scan's plane map (`map planes --options
presets/room-map.yaml`, with its recall of the GT planes of 1 m^2 and more), then, all with
`--deterministic --config presets/room-run.yaml`:

  vo      --init-pose-from poses/00.txt --no-planes
  plane   --init-pose-from poses/00.txt --planes planes.json --init-sigma "0 0 0"
  prior   --init-pose-from poses/00.txt --planes planes.json --init-sigma "0.5 0.5 10": the
          exact start given as a user would, with the room's prior (issue 30: never worse than
          the exact start)
  draw k  the first GT pose moved by a seeded draw (numpy default_rng(seed * 100 + k)) of a
          translation uniform in a ball of 0.5 m and a yaw uniform in +-10 deg about the map's z,
          --init-pose ... --planes planes.json --init-sigma "0.5 0.5 10"

ATE = RMSE of the camera positions against poses/00.txt, no alignment. For the draws also the
RMSE and the max of the error from 20 frames after the first "locked" on; a wrong lock is a lock
whose error 20 frames later is over 0.1 m. fps, lost frames and the map lock come from each run's
log. The section "Indoors: the room preset" of docs/benchmarks.md is rendered from it by
scripts/bench_report_room.py.

Usage: scripts/bench_room.py [--build build] [--out build/bench/room.json]
                             [--work build/bench/data/room] [--seeds 1,2,3] [--frames 600]
                             [--draws 3]
On 2 cores: about 35 minutes when the drives must be simulated (7 minutes each), about 15 when
they are cached (per seed six runs of about 50 s).
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

from bench_run import cpu_model, tree_commit

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRESET_FRAMES = 600  # the room preset's
OFFSET_M, YAW_DEG = 0.5, 10.0  # the coarse start's draw
COARSE_SIGMA = "0.5 0.5 10"
SETTLE = 20  # frames after the lock before its error counts
WRONG_M = 0.1


def sh(cmd, log):
    """(exit code, wall seconds) of cmd, its output in log."""
    start = time.monotonic()
    with open(log, "w") as f:
        code = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT).returncode
    return code, time.monotonic() - start


def check(cmd, log):
    code, _ = sh(cmd, log)
    if code != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {code} (log {log})")


def readme(path):
    """The 'key: value' lines of a simulated world's README.txt ({} when missing)."""
    try:
        with open(path) as f:
            return dict(line.split(": ", 1) for line in f.read().splitlines() if ": " in line)
    except OSError:
        return {}


def prepare(planeloc, work, seed, frames):
    """The seed's folder, its README and planes.json's stats; simulated and mapped when needed."""
    data = os.path.join(work, f"room_s{seed}")
    info = readme(os.path.join(data, "world", "README.txt"))
    if info.get("seed") != str(seed) or info.get("frames") != str(frames):
        os.makedirs(data, exist_ok=True)
        check([planeloc, "sim", "--preset", "room", "--seed", str(seed), "--frames", str(frames),
               "--out", data, "--force"], os.path.join(work, f"sim_s{seed}.log"))
        info = readme(os.path.join(data, "world", "README.txt"))
    ply = os.path.join(data, "mav0", "pointcloud0", "data.ply")
    planes = os.path.join(data, "planes.json")
    if not os.path.exists(planes) or os.path.getmtime(planes) < os.path.getmtime(ply):
        check([planeloc, "map", "planes", "--map", ply, "--out", planes, "--up", "0", "0", "1",
               "--options", os.path.join(ROOT, "presets", "room-map.yaml"),
               "--gt", os.path.join(data, "world", "planes_gt.json"), "--gt-min-area", "1",
               "--gt-all-kinds"], os.path.join(work, f"planes_s{seed}.log"))
    with open(planes) as f:
        plane_map = json.load(f)
    return data, info, plane_map


def load_poses(path):
    """(n, 3, 4) world_from_cam of a KITTI pose file."""
    return np.loadtxt(path, ndmin=2).reshape(-1, 3, 4)


def errors(est_path, gt):
    """Per-frame position error (m) of a trajectory against the GT poses, no alignment."""
    est = load_poses(est_path)
    if est.shape != gt.shape:
        raise ValueError(f"{est_path}: {len(est)} poses, the ground truth has {len(gt)}")
    return np.linalg.norm(est[:, :, 3] - gt[:, :, 3], axis=1)


def metres(x):
    return "-" if x is None else f"{x:.3f} m"


def rmse(e):
    return float(np.sqrt(np.mean(e ** 2))) if len(e) else None


def coarse_start(first, seed, k):
    """The first GT pose moved by draw k: (3x4 pose, offset m, yaw deg)."""
    rng = np.random.default_rng(seed * 100 + k)
    direction = rng.normal(size=3)
    d = direction / np.linalg.norm(direction) * OFFSET_M * rng.uniform() ** (1 / 3)
    yaw = rng.uniform(-YAW_DEG, YAW_DEG)
    c, s = np.cos(np.radians(yaw)), np.sin(np.radians(yaw))
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    pose = np.hstack([rz @ first[:, :3], (first[:, 3] + d)[:, None]])
    return pose, float(np.linalg.norm(d)), float(yaw)


def track(planeloc, data, out, args):
    """One `planeloc run`: its wall time, fps, lost frames and map lock from the log; 'error' when
    it failed."""
    log = out[:-4] + ".log"
    cmd = [planeloc, "run", "--sequence", os.path.join(data, "mav0"), "--deterministic",
           "--config", os.path.join(ROOT, "presets", "room-run.yaml"), "--out", out] + args
    code, wall = sh(cmd, log)
    with open(log) as f:
        text = f.read()
    row = {"wall_s": round(wall, 1), "fps": None, "lost": None, "locked_frame": None,
           "final_lock": None}
    m = re.search(r"(\d+) frames in [\d.]+ s \(([\d.]+) fps\): \d+ tracked, (\d+) lost", text)
    if m:
        row.update(fps=float(m.group(2)), lost=int(m.group(3)))
    m = re.search(r"map lock: locked at frame (\d+)", text)
    if m:
        row["locked_frame"] = int(m.group(1))
    m = re.search(r"map lock at the end: (\w+)|\(map lock: (searching)\)", text)
    if m:
        row["final_lock"] = m.group(1) or m.group(2)
    if code != 0:
        row["error"] = f"exit {code} (log {log})"
    return row


def with_ate(row, out, gt):
    """Sets row's ate and returns the per-frame errors; None, and row's error, when the run failed
    or its trajectory does not fit the ground truth."""
    row["ate"] = None
    if "error" not in row:
        try:
            e = errors(out, gt)
            row["ate"] = rmse(e)
            return e
        except (OSError, ValueError) as err:
            row["error"] = str(err)
    return None


def one_seed(planeloc, work, seed, frames, draws):
    data, info, plane_map = prepare(planeloc, work, seed, frames)
    gt_eval = plane_map.get("stats", {}).get("gt_evaluation", {})
    checked = gt_eval.get("checked")
    gt_path = os.path.join(data, "poses", "00.txt")
    gt = load_poses(gt_path)
    planes = os.path.join(data, "planes.json")
    runs = os.path.join(work, "runs", f"room_s{seed}")
    os.makedirs(runs, exist_ok=True)
    result = {
        "seed": seed,
        "path_length_m": float(info["path_length_m"]) if "path_length_m" in info else None,
        "gt_planes_checked": len(checked) if isinstance(checked, list) else checked,
        "gt_planes_good": gt_eval.get("good"), "planes": len(plane_map["planes"]),
    }
    for name, extra in (("vo", ["--init-pose-from", gt_path, "--no-planes"]),
                        ("plane", ["--init-pose-from", gt_path, "--planes", planes,
                                   "--init-sigma", "0 0 0"]),
                        ("prior", ["--init-pose-from", gt_path, "--planes", planes,
                                   "--init-sigma", COARSE_SIGMA])):
        out = os.path.join(runs, f"{name}.txt")
        row = track(planeloc, data, out, extra)
        with_ate(row, out, gt)
        result[name] = {k: row[k] for k in ("ate", "fps", "lost", "wall_s", "error",
                                            "locked_frame", "final_lock") if k in row}
        print(f"seed {seed} {name}: ATE {metres(row['ate'])}, {row['fps']} fps, {row['lost']} lost"
              + (f", {row['error']}" if "error" in row else ""), flush=True)
    result["draws"] = []
    for k in range(1, draws + 1):
        pose, offset, yaw = coarse_start(gt[0], seed, k)
        out = os.path.join(runs, f"coarse{k}.txt")
        row = track(planeloc, data, out, [
            "--init-pose", " ".join(f"{x:.9f}" for x in pose.ravel()), "--planes", planes,
            "--init-sigma", COARSE_SIGMA])
        e = with_ate(row, out, gt)
        lock = row["locked_frame"]
        after = e[lock + SETTLE:] if e is not None and lock is not None else np.empty(0)
        wrong = bool(after[0] > WRONG_M) if len(after) else None
        row = dict(k=k, offset_m=round(offset, 4), yaw_deg=round(yaw, 3), **row,
                   ate_after_lock=rmse(after),
                   max_after_lock=float(after.max()) if len(after) else None,
                   wrong=False if lock is None and e is not None else wrong)
        result["draws"].append(row)
        print(f"seed {seed} draw {k} ({offset:.2f} m, {yaw:+.1f} deg): lock {lock} "
              f"({row['final_lock']}), ATE after it {metres(row['ate_after_lock'])}, wrong "
              f"{row['wrong']}" + (f", {row['error']}" if "error" in row else ""), flush=True)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--out", default=None)
    parser.add_argument("--work", default=None)
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--frames", type=int, default=PRESET_FRAMES)
    parser.add_argument("--draws", type=int, default=3)
    args = parser.parse_args()
    out = args.out or os.path.join(args.build, "bench", "room.json")
    work = args.work or os.path.join(args.build, "bench", "data", "room")
    planeloc = os.path.join(args.build, "bin", "planeloc")
    seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
    commit = tree_commit("-dirty")
    os.makedirs(work, exist_ok=True)
    load_start = list(os.getloadavg())
    results = []
    for seed in seeds:
        try:
            results.append(one_seed(planeloc, work, seed, args.frames, args.draws))
        except (RuntimeError, OSError, ValueError, KeyError) as e:  # no drive or no plane map
            print(f"seed {seed}: {e}", file=sys.stderr)
            results.append({"seed": seed, "error": str(e)})
    result = {
        "date": datetime.date.today().isoformat(), "commit": commit, "cpu": cpu_model(),
        "cpus": os.cpu_count(), "frames": args.frames,
        "command": f"scripts/bench_room.py --seeds {','.join(map(str, seeds))} "
                   f"--frames {args.frames} --draws {args.draws}",
        "seeds": results,
        # What else ran on the machine: fps are only comparable between runs on an idle one.
        "load_start": load_start, "load_end": list(os.getloadavg()),
    }
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
