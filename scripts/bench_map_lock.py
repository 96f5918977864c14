#!/usr/bin/env python3
"""Map-lock benchmark (issue 9): `planeloc run --planes` from coarse start poses.

For each preset and seed it renders the synthetic town (cached), builds the LiDAR map and the
plane map, then runs plane mode from start poses perturbed by draws from a prior and reports:
  - when the run locked (frame, distance driven), whether it locked before 60 m or the first
    corner, and whether the lock was wrong (pose error at the lock > 0.5 m or 2 deg; for a
    partial lock only the registered DoF count: lateral, vertical, heading);
  - the ATE RMSE (no alignment: the map fixes the frame) over the frames after the lock;
  - the same frames for the visual-only baseline and for plane mode from the exact start.
Every plane-mode run also writes `--out-final` (the frames before the lock re-expressed by the
lock's correction, pipeline/final_trajectory.h); its ATE over all frames is `*_final_m`.
With --exact-start (issue 30) it also runs the default prior from the *exact* start pose, which
must never end worse than the exact start itself (`--init-sigma "0 0 0"`): ATE over all frames,
its ratio to the exact start, and VO on the same frames.
Every run's applied corrections are checked against their gate from the stats (each registered
DoF within 3 sigma of its innovation sigma), and the most planes disabled at once is reported
(on a clean map every disabled plane is a correct one).
Writes JSON (--json) and prints a Markdown table. Every draw is seeded: reruns are identical.

Usage: scripts/bench_map_lock.py [--planeloc build/bin/planeloc] [--work /tmp/planeloc-maplock]
         [--preset small] [--seeds 3 11] [--draws 20] [--sigma "2 0.5 5"] [--exact-start]
         [--json out.json] [--config settings.yaml]
"""
import argparse
import hashlib
import json
import math
import os
import random
import subprocess
import sys
import time

UP = (0.0, -1.0, 0.0)  # KITTI camera world: y down


def run(cmd, log):
    with open(log, "a") as f:
        f.write("$ " + " ".join(cmd) + "\n")
        f.flush()
        return subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT).returncode


def read_kitti(path):
    poses = []
    with open(path) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            if len(v) == 12:
                poses.append(v)
    return poses


def position(p):
    return (p[3], p[7], p[11])


def rotation(p):
    return ((p[0], p[1], p[2]), (p[4], p[5], p[6]), (p[8], p[9], p[10]))


def matmul(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))


def transpose(a):
    return tuple(tuple(a[j][i] for j in range(3)) for i in range(3))


def rot_y(angle):  # rotation about the KITTI world's vertical axis (y)
    c, s = math.cos(angle), math.sin(angle)
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def angle_of(r):
    trace = r[0][0] + r[1][1] + r[2][2]
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1.0) / 2.0))))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def norm(a):
    return math.sqrt(sum(x * x for x in a))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def perturb(pose, dx, dz, dy_up, yaw_deg):
    """The start pose moved by (dx, dz) horizontally, dy_up up and rotated by yaw about up."""
    r = matmul(rot_y(math.radians(yaw_deg)), rotation(pose))
    t = position(pose)
    t = (t[0] + dx, t[1] - dy_up, t[2] + dz)
    return " ".join(f"{x:.9f}" for x in (r[0] + (t[0],) + r[1] + (t[1],) + r[2] + (t[2],)))


def heading(pose):
    r = rotation(pose)
    forward = (r[0][2], r[2][2])  # camera z in the world x-z plane
    return math.atan2(forward[0], forward[1])


def first_corner_end(gt):
    """Frame where the heading has changed by 45 deg from the start, plus 20 frames; None."""
    h0 = heading(gt[0])
    for i, p in enumerate(gt):
        d = math.degrees(abs(math.atan2(math.sin(heading(p) - h0), math.cos(heading(p) - h0))))
        if d > 45.0:
            return min(len(gt) - 1, i + 20)
    return None


def distances(gt):
    out, s = [0.0], 0.0
    for a, b in zip(gt, gt[1:]):
        s += norm(sub(position(b), position(a)))
        out.append(s)
    return out


def pose_errors(est, gt, i):
    """(translation error, lateral, vertical, along, heading error deg, rotation error deg)."""
    e, g = est[i], gt[i]
    d = sub(position(e), position(g))
    r = rotation(g)
    forward = (r[0][2], 0.0, r[2][2])
    fn = norm(forward) or 1.0
    forward = tuple(x / fn for x in forward)
    lateral = (forward[2], 0.0, -forward[0])
    rel = matmul(transpose(rotation(g)), rotation(e))
    yaw = math.degrees(abs(math.atan2(math.sin(heading(e) - heading(g)),
                                      math.cos(heading(e) - heading(g)))))
    return (norm(d), abs(dot(d, lateral)), abs(d[1]), abs(dot(d, forward)), yaw, angle_of(rel))


def ate(est, gt, start):
    n = len(gt) - start
    if n <= 0:
        return float("nan")
    return math.sqrt(sum(norm(sub(position(est[i]), position(gt[i]))) ** 2
                         for i in range(start, len(gt))) / n)


def read_stats(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def check_corrections(stats, limit=3.0):
    """(applied corrections, those beyond `limit` sigma in a registered DoF, worst ratio)."""
    applied, beyond, worst = 0, 0, 0.0
    for s in stats:
        reg = s.get("registration")
        if not reg or not reg.get("applied"):
            continue
        applied += 1
        fusion = reg.get("fusion")
        if not fusion:  # an applied correction without its gate: counts as a violation
            beyond += 1
            continue
        ratio = 0.0
        for dof, value in fusion["applied"].items():
            sigma = fusion["innovation_sigma"].get(dof)
            if value is None or sigma is None or value == 0.0:
                continue
            ratio = max(ratio, abs(value) / sigma)
        worst = max(worst, ratio)
        if ratio > limit + 1e-6:
            beyond += 1
    return applied, beyond, worst


def max_disabled(stats):
    return max((s.get("planes_disabled", 0) for s in stats), default=0)


def prepare(args, preset, seed):
    work = os.path.join(args.work, f"{preset}-{seed}")
    log = os.path.join(work, "log.txt")
    os.makedirs(work, exist_ok=True)
    seq = os.path.join(work, "sim", "sequences", "00")
    poses = os.path.join(work, "sim", "poses", "00.txt")
    planes = os.path.join(work, "planes.json")
    if not os.path.exists(planes):
        steps = [
            [args.planeloc, "sim", "--out", os.path.join(work, "sim"), "--preset", preset,
             "--seed", str(seed), "--force"],
            [args.planeloc, "map", "build", "--sequence", seq, "--poses", poses, "--out",
             os.path.join(work, "map.pcd")],
            [args.planeloc, "map", "planes", "--map", os.path.join(work, "map.pcd"), "--out",
             planes],
        ]
        for cmd in steps:
            if run(cmd, log) != 0:
                sys.exit(f"failed: {' '.join(cmd)} (log: {log})")
    return work, seq, poses, planes, log


def run_plane_mode(args, seq, planes, init_pose, sigma, out, log, extra=()):
    cmd = [args.planeloc, "run", "--sequence", seq, "--init-pose", init_pose, "--planes", planes,
           "--init-sigma", sigma, "--out", out + ".txt", "--out-final", out + ".final.txt",
           "--stats", out + ".jsonl", "--deterministic"] + list(extra)
    if args.config:
        cmd += ["--config", args.config]
    start = time.time()
    rc = run(cmd, log)
    return rc, time.time() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--planeloc", default="build/bin/planeloc")
    ap.add_argument("--work", default="/tmp/planeloc-maplock")
    ap.add_argument("--preset", default="small")
    ap.add_argument("--seeds", type=int, nargs="+", default=[3, 11])
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--sigma", default="2 0.5 5", help="prior of the draws and of the run")
    ap.add_argument("--lock-distance", type=float, default=60.0)
    ap.add_argument("--exact-start", action="store_true",
                    help="also run the prior from the exact start (issue 30)")
    ap.add_argument("--json", default="")
    ap.add_argument("--config", default="",
                    help="settings file for every plane-mode run (an option under test)")
    args = ap.parse_args()
    s_xy, s_z, s_yaw = (float(x) for x in args.sigma.split())

    with open(args.planeloc, "rb") as f:
        binary_id = hashlib.sha1(f.read()).hexdigest()[:10]
    rows = []
    for seed in args.seeds:
        work, seq, poses, planes, log = prepare(args, args.preset, seed)
        gt = read_kitti(poses)
        dist = distances(gt)
        corner = first_corner_end(gt)
        exact_pose = " ".join(f"{x:.9f}" for x in gt[0])
        # References on the same frames, by the same binary (cached per binary): exact start
        # with planes, and visual odometry.
        ref = os.path.join(work, f"exact-{binary_id}")
        if not os.path.exists(ref + ".txt"):
            run_plane_mode(args, seq, planes, exact_pose, "0 0 0", ref, log)
        vo = os.path.join(work, f"vo-{binary_id}")
        if not os.path.exists(vo + ".txt"):
            run([args.planeloc, "run", "--sequence", seq, "--init-pose", exact_pose, "--no-planes",
                 "--out", vo + ".txt", "--deterministic"], log)
        exact_est, vo_est = read_kitti(ref + ".txt"), read_kitti(vo + ".txt")
        if args.exact_start:
            out = os.path.join(work, f"exactprior-{args.sigma.replace(' ', '_')}")
            rc, seconds = run_plane_mode(args, seq, planes, exact_pose, args.sigma, out, log)
            row = {"preset": args.preset, "seed": seed, "draw": "exact", "rc": rc,
                   "seconds": seconds}
            if rc == 0:
                est, stats = read_kitti(out + ".txt"), read_stats(out + ".jsonl")
                applied, beyond, worst = check_corrections(stats)
                row.update({
                    "ate_all_frames_m": ate(est, gt, 0),
                    "ate_all_frames_final_m": ate(read_kitti(out + ".final.txt"), gt, 0),
                    "ate_exact_start_m": ate(exact_est, gt, 0),
                    "ate_vo_m": ate(vo_est, gt, 0),
                    "corrections": applied, "corrections_beyond_3sigma": beyond,
                    "worst_correction_sigmas": worst, "max_planes_disabled": max_disabled(stats),
                    "final_lock": stats[-1].get("map_lock") if stats else None})
                row["ratio_to_exact"] = row["ate_all_frames_m"] / row["ate_exact_start_m"]
            rows.append(row)
            print(json.dumps(row), flush=True)
        for k in range(args.draws):
            rng = random.Random(seed * 1000 + k)
            dx, dz = rng.gauss(0, s_xy), rng.gauss(0, s_xy)
            dy, yaw = rng.gauss(0, s_z), rng.gauss(0, s_yaw)
            out = os.path.join(work, f"draw{k:02d}-{args.sigma.replace(' ', '_')}")
            rc, seconds = run_plane_mode(args, seq, planes, perturb(gt[0], dx, dz, dy, yaw),
                                         args.sigma, out, log)
            row = {"preset": args.preset, "seed": seed, "draw": k, "rc": rc, "seconds": seconds,
                   "start_error": {"horizontal_m": math.hypot(dx, dz), "vertical_m": abs(dy),
                                   "yaw_deg": abs(yaw)}}
            if rc == 0:
                est = read_kitti(out + ".txt")
                stats = read_stats(out + ".jsonl")
                locked = next((s["frame"] for s in stats if s.get("map_lock") == "locked"), None)
                partial = next((s["frame"] for s in stats
                                if s.get("map_lock") in ("partial", "locked")), None)
                row.update({"lock_frame": locked, "partial_frame": partial})
                wrong = False
                if locked is not None:
                    row["lock_distance_m"] = dist[locked]
                    errors = [pose_errors(est, gt, i) for i in range(locked, min(len(gt), locked + 5))]
                    worst_t = max(e[0] for e in errors)
                    worst_r = max(e[5] for e in errors)
                    row["error_at_lock"] = {"translation_m": worst_t, "rotation_deg": worst_r}
                    wrong = worst_t > 0.5 or worst_r > 2.0
                    row["ate_after_lock_m"] = ate(est, gt, locked)
                    row["ate_exact_start_same_frames_m"] = ate(exact_est, gt, locked)
                    row["ate_vo_same_frames_m"] = ate(vo_est, gt, locked)
                if partial is not None and (locked is None or partial < locked):
                    errors = [pose_errors(est, gt, i) for i in range(partial, min(len(gt), partial + 5))]
                    row["error_at_partial"] = {"lateral_m": max(e[1] for e in errors),
                                               "vertical_m": max(e[2] for e in errors),
                                               "yaw_deg": max(e[4] for e in errors)}
                    e = row["error_at_partial"]
                    wrong = wrong or e["lateral_m"] > 0.5 or e["vertical_m"] > 0.5 or e["yaw_deg"] > 2
                first = partial if partial is not None else locked
                row["lock_in_time"] = locked is not None and (
                    dist[locked] <= args.lock_distance or (corner is not None and locked <= corner))
                row["wrong_lock"] = wrong
                row["ate_all_frames_m"] = ate(est, gt, 0)
                row["ate_all_frames_final_m"] = ate(read_kitti(out + ".final.txt"), gt, 0)
                row["ate_vo_all_frames_m"] = ate(vo_est, gt, 0)
                applied, beyond, worst = check_corrections(stats)
                row.update({"corrections": applied, "corrections_beyond_3sigma": beyond,
                            "worst_correction_sigmas": worst,
                            "max_planes_disabled": max_disabled(stats)})
                if first is not None:
                    row["ate_after_first_lock_m"] = ate(est, gt, first)
            rows.append(row)
            print(json.dumps(row), flush=True)

    ok = [r for r in rows if r["rc"] == 0 and r["draw"] != "exact"]
    exact_rows = [r for r in rows if r["rc"] == 0 and r["draw"] == "exact"]
    locked = [r for r in ok if r.get("lock_frame") is not None]
    summary = {
        "preset": args.preset, "seeds": args.seeds, "draws_per_seed": args.draws,
        "sigma": args.sigma, "runs": len(rows),
        "failed_runs": sum(1 for r in rows if r["rc"] != 0),
        "locked": len(locked), "locked_in_time": sum(1 for r in ok if r.get("lock_in_time")),
        "wrong_locks": sum(1 for r in ok if r.get("wrong_lock")),
        "ate_after_lock_mean_m": (sum(r["ate_after_lock_m"] for r in locked) / len(locked)
                                  if locked else None),
        "ate_after_lock_max_m": max((r["ate_after_lock_m"] for r in locked), default=None),
        "ate_exact_start_same_frames_mean_m": (
            sum(r["ate_exact_start_same_frames_m"] for r in locked) / len(locked) if locked else None),
        "ate_vo_same_frames_mean_m": (sum(r["ate_vo_same_frames_m"] for r in locked) / len(locked)
                                      if locked else None),
        "draws_above_vo_all_frames": sum(
            1 for r in ok if r.get("ate_all_frames_m", 0) > r.get("ate_vo_all_frames_m", 1e9)),
        "draws_above_vo_all_frames_final": sum(
            1 for r in ok
            if r.get("ate_all_frames_final_m", 0) > r.get("ate_vo_all_frames_m", 1e9)),
        "draws_all_frames_final_mean_m": (
            sum(r["ate_all_frames_final_m"] for r in ok) / len(ok) if ok else None),
        "draws_after_lock_above_1.1x_exact": sum(
            1 for r in locked
            if r["ate_after_lock_m"] > 1.1 * r["ate_exact_start_same_frames_m"]),
        "exact_start_worst_ratio": max((r["ratio_to_exact"] for r in exact_rows), default=None),
        "exact_start_above_vo": sum(1 for r in exact_rows if r["ate_all_frames_m"] > r["ate_vo_m"]),
        "corrections": sum(r.get("corrections", 0) for r in rows),
        "corrections_beyond_3sigma": sum(r.get("corrections_beyond_3sigma", 0) for r in rows),
        "runs_with_disabled_planes": sum(1 for r in rows if r.get("max_planes_disabled", 0) > 0),
        "lock_distance_median_m": (sorted(r["lock_distance_m"] for r in locked)[len(locked) // 2]
                                   if locked else None),
    }
    print(json.dumps(summary, indent=1))
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            json.dump({"summary": summary, "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
