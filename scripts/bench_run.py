#!/usr/bin/env python3
"""Runs planeloc's benchmarks and writes their results as JSON (issue 12 item 4).

Called by scripts/bench.sh after the Release build; scripts/bench_report.py turns the results into
docs/benchmarks.md. Writes, under --out (build/bench by default):

  meta.json      machine and run: dates, CPU model, logical CPUs, commit, load average at start and
                 end, quick or full, and the command of every Google Benchmark program
  gbench/*.json  Google Benchmark output (--benchmark_out) of each program
  pipeline.json  per simulated drive: sim, map build, map planes (cached under data/); per run of
                 `planeloc run` (plane mode and visual odometry, threaded and --deterministic, and
                 LocalBA.lambda 1): wall time, peak RSS, frames per second, ATE 3-D and 2-D and
                 KITTI drift from `planeloc eval`
  robustness.json  full mode only, issue 10 item 5: per drive of WRONG_MAP_DRIVES the ATE with
                 the plane map, wrong copies of it, a map from noisy poses (as it is and refined
                 by `map refine-poses`), the oracle map and no map (scripts/bench_wrong_map.sh); the ablation of ABLATION_VARIANTS on
                 ABLATION_DRIVE (scripts/bench_ablation.sh)
  maplock.json   full mode only, issue 30: rows of scripts/bench_map_lock.py, the default prior
                 from the exact start on MAP_LOCK_EXACT_DRIVES and draws from the prior on
                 MAP_LOCK_DRAW_DRIVES; with --only-map-lock this file alone, carrying its own run
                 (date, CPU, commit) for scripts/bench_report_map_lock.py --splice
  data/<preset>-<seed>/  simulator output, map.pcd, planes.json (reused by later runs; --fresh
                 rebuilds them) and steps.json (how they were made: commands, wall time, peak RSS);
                 the wrong maps and the runs on them (wrong-map/, abl-<variant>/)
  runs/<preset>-<seed>/  trajectories, stats, logs and eval JSON of the runs

Peak RSS is the child's ru_maxrss from wait4(2); no sampling. Quick mode (--quick, under 5 minutes
on a 2-core machine) runs the tiny preset once and a filtered subset of the Google Benchmark
programs with short minimum times; full mode runs every benchmark, small seeds 3, 11, 21 and
kitti07-like seeds 1, 2 (about an hour, most of it kitti07-like's simulation and plane map).

Usage: scripts/bench_run.py [--build build] [--out BUILD/bench] [--quick] [--fresh]
                            [--drives "small:3,11,21 kitti07-like:1"] [--no-robustness]
                            [--no-map-lock]
--drives replaces the mode's drives (the benchmarks stay the mode's); the page then says so.
"""
import argparse
import datetime
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Drives of the accuracy tables: (preset, seeds).
QUICK_DRIVES = [("tiny", [1])]
FULL_DRIVES = [("small", [3, 11, 21]), ("kitti07-like", [1, 2])]

# KITTI drift averages over 100..800 m segments: shorter paths have none.
KITTI_MIN_PATH_M = 100.0

LAMBDA1_SETTINGS = "%YAML:1.0\nLocalBA.lambda: 1\n"

# Issue 10's acceptance benchmark (full mode): drives with wrong maps, the columns of
# scripts/bench_wrong_map.sh they run, and the ablation (scripts/bench_ablation.sh). Seeds 3, 11
# and 21 of `small` tuned the association; 7, 13 and 29 did not (7 and 13 were diagnosed).
WRONG_MAP_DRIVES = [("small", [3, 11, 21, 7, 13, 29]), ("tiny", [3, 11, 21])]
WRONG_MAP_KINDS = ["vo", "clean", "move0.1", "move0.2", "move0.3", "rot2", "oracle", "noisy",
                   "refined"]
ABLATION_DRIVE = ("small", [3, 11, 21])
ABLATION_KINDS = ["clean", "move0.2"]
ABLATION_VARIANTS = ["default", "lambda1", "lambda0.8", "lambda0.2", "fixedwindow", "oldgate",
                     "noconsensus"]

# Issue 30's acceptance benchmark (full mode, scripts/bench_map_lock.py): the default prior from
# the exact start on every drive (seeds 41, 43 and 47 are used by no test and no tuning), and
# start poses drawn from the prior on the bench's small drives.
MAP_LOCK_EXACT_DRIVES = [("tiny", [3, 5, 11, 21, 41, 43, 47]), ("small", [3, 11, 21, 41, 43, 47]),
                         ("kitti07-like", [1, 2])]
MAP_LOCK_DRAW_DRIVES = [("small", [3, 11, 21])]
MAP_LOCK_DRAWS = 20

# Runs of `planeloc run` per drive: (name, plane map?, --deterministic?, settings file).
RUNS = [
    ("planes-threaded", True, False, None),
    ("planes-deterministic", True, True, None),
    ("vo-threaded", False, False, None),
    ("vo-deterministic", False, True, None),
    ("planes-lambda1-deterministic", True, True, "lambda1.yaml"),
]


class BenchError(Exception):
    """A step failed: the message says which and where its log is."""


def rel(path):
    """Path relative to the repository root when inside it (for readable commands)."""
    path = os.path.abspath(path)
    return os.path.relpath(path, ROOT) if path.startswith(ROOT + os.sep) else path


def command_text(cmd, env=None):
    """The command as a user would type it from the repository root."""
    words = [rel(w) if os.path.isabs(w) else w for w in cmd]
    prefix = "".join(f"{k}={shlex.quote(rel(v))} " for k, v in sorted((env or {}).items()))
    return prefix + shlex.join(words)


def run_measured(cmd, log_path, env=None):
    """Runs cmd with output to log_path; returns wall seconds and peak RSS (MB) of the process."""
    full_env = dict(os.environ, **(env or {}))
    start = time.monotonic()
    with open(log_path, "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=full_env)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    wall = time.monotonic() - start
    if proc.returncode != 0:
        raise BenchError(f"exit code {proc.returncode}: {command_text(cmd)} (log: {rel(log_path)})")
    return {
        "command": command_text(cmd, env),
        "wall_s": round(wall, 3),
        "peak_rss_mb": round(usage.ru_maxrss / 1024.0, 1),  # kB on Linux
        "user_cpu_s": round(usage.ru_utime, 2),
        "system_cpu_s": round(usage.ru_stime, 2),
    }


def git(*args):
    try:
        return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def tree_commit(dirty_marker):
    """HEAD's short hash, with `dirty_marker` appended when tracked files differ from it: the tree
    the binary was built from, read before a benchmark's runs."""
    commit = git("rev-parse", "--short", "HEAD")
    return commit + dirty_marker if git("status", "--porcelain", "--untracked-files=no") else commit


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def now_utc():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def parse_drives(text):
    """'small:3,11 tiny:1' -> [("small", [3, 11]), ("tiny", [1])]."""
    drives = []
    for item in text.split():
        preset, _, seeds = item.partition(":")
        try:
            drives.append((preset, [int(s) for s in seeds.split(",")]))
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{item}': expected PRESET:SEED[,SEED...]")
    if not drives:
        raise argparse.ArgumentTypeError("no drive given")
    return drives


def machine_and_commit(build_dir, quick):
    build_type = ""
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if os.path.exists(cache):
        with open(cache) as f:
            for line in f:
                if line.startswith("CMAKE_BUILD_TYPE:"):
                    build_type = line.split("=", 1)[1].strip()
    dirty = git("status", "--porcelain", "--untracked-files=no")
    return {
        "mode": "quick" if quick else "full",
        "command": "scripts/bench.sh --quick" if quick else "scripts/bench.sh",
        "start": now_utc(),
        "load_start": list(os.getloadavg()),
        "cpu_model": cpu_model(),
        "logical_cpus": len(os.sched_getaffinity(0)),
        "commit": git("rev-parse", "--short=7", "HEAD") or "unknown",
        "commit_subject": git("log", "-1", "--format=%s"),
        "dirty": bool(dirty),
        "build_dir": rel(build_dir),
        "build_type": build_type,
    }


def gbench_plan(quick, data_dir):
    """(program, extra arguments, environment) of each Google Benchmark program to run."""
    if quick:
        return [
            ("features_bench", ["--benchmark_filter=BM_OrbExtractOneImage/threads:1$|"
                                "BM_CvOrbDetectAndCompute|BM_StereoExtractAndMatch/threads:2$",
                                "--benchmark_min_time=0.3"], {}),
            ("map_bench", ["--benchmark_filter=BM_TensorVotingNormals/3/2/|"
                           "BM_TensorVotingNormalsMortonInput/3/|BM_Open3dEstimateNormals/3/"],
             {"PLANELOC_BENCH_MAP_POINTS": "200000"}),
            ("optim_bench", ["--benchmark_filter=BM_SolveWindowBa/10/2000/|BM_Evaluate|"
                             "BM_OptimizePoseStereo/1000", "--benchmark_min_time=0.3"], {}),
        ]
    small = os.path.join(data_dir, "small-3")
    return [
        ("features_bench", [], {}),
        ("map_bench", [], {}),
        ("optim_bench", [], {}),
        ("tracking_bench", [], {"PLANELOC_BENCH_SIM_SMALL": os.path.join(small, "sim")}),
        ("crease_bench", [], {"PLANELOC_CREASE_BENCH_DIR": small}),
        ("rectify_bench", [], {}),
        ("sim_bench", [], {}),
        ("map_density_bench", [], {}),
    ]


def run_gbench(bin_dir, out_dir, quick, data_dir):
    gbench_dir = os.path.join(out_dir, "gbench")
    os.makedirs(gbench_dir, exist_ok=True)
    records = []
    for program, args, env in gbench_plan(quick, data_dir):
        exe = os.path.join(bin_dir, program)
        json_path = os.path.join(gbench_dir, program + ".json")
        cmd = [exe, *args]
        print(f"=== {command_text(cmd, env)}", flush=True)
        record = {"program": program, "command": command_text(cmd, env), "json": rel(json_path)}
        if not os.path.exists(exe):
            raise BenchError(f"{rel(exe)} not built (scripts/build.sh builds it)")
        if os.path.exists(json_path):
            os.remove(json_path)
        record.update(run_measured(
            cmd + [f"--benchmark_out={json_path}", "--benchmark_out_format=json"],
            os.path.join(gbench_dir, program + ".log"), env))
        record["command"] = command_text(cmd, env)  # without the --benchmark_out plumbing
        records.append(record)
    return records


def path_length_m(poses_path):
    """Length of a KITTI pose file's path, metres."""
    length, last = 0.0, None
    with open(poses_path) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            if len(v) != 12:
                continue
            p = (v[3], v[7], v[11])
            if last is not None:
                length += math.dist(p, last)
            last = p
    return length


def prepare_drive(planeloc, data_dir, preset, seed, fresh, lighting=None):
    """Simulator output and plane map of one drive, made once and reused (steps.json); `lighting`
    other than the simulator's default (e.g. "changing") is a drive of its own."""
    d = os.path.join(data_dir, f"{preset}-{seed}" + (f"-{lighting}" if lighting else ""))
    steps_path = os.path.join(d, "steps.json")
    if fresh and os.path.exists(d):
        shutil.rmtree(d)
    steps = {}
    if os.path.exists(steps_path):
        with open(steps_path) as f:
            steps = json.load(f)
    os.makedirs(d, exist_ok=True)
    sim, map_pcd, planes = (os.path.join(d, n) for n in ("sim", "map.pcd", "planes.json"))
    poses = os.path.join(sim, "poses", "00.txt")
    plan = [
        ("sim", [planeloc, "sim", "--out", sim, "--preset", preset, "--seed", str(seed),
                 "--force"] + (["--lighting", lighting] if lighting else [])),
        ("map build", [planeloc, "map", "build", "--sequence", os.path.join(sim, "sequences", "00"),
                       "--poses", poses, "--out", map_pcd, "--voxel", "0.10"]),
        ("map planes", [planeloc, "map", "planes", "--map", map_pcd, "--out", planes]),
    ]
    commit = git("rev-parse", "--short=7", "HEAD")
    made = set()  # a remade step invalidates the later ones
    for name, cmd in plan:
        if name in steps and not made:
            print(f"--- {preset} seed {seed}: {name} cached ({rel(d)})", flush=True)
            continue
        made.add(name)
        print(f"--- {preset} seed {seed}: {name}", flush=True)
        record = run_measured(cmd, os.path.join(d, name.replace(" ", "_") + ".log"))
        record.update({"date": now_utc(), "commit": commit})
        steps[name] = record
        with open(steps_path, "w") as f:  # after each step: an interrupted run resumes
            json.dump(steps, f, indent=1)
    with open(poses) as f:
        frames = sum(1 for line in f if line.strip())
    return {"preset": preset, "seed": seed, "dir": rel(d), "frames": frames,
            "path_m": round(path_length_m(poses), 1),
            "steps": [dict(steps[name], step=name, cached=name not in made) for name, _ in plan]}


def evaluate(planeloc, poses, traj, out_prefix, kitti):
    """ATE RMSE 3-D and 2-D (ground plane xz), no alignment, and KITTI drift when defined."""
    result = {}
    for kind, extra in (("3d", ["--kitti-drift"] if kitti else []), ("2d", ["--plane", "xz"])):
        json_path = f"{out_prefix}.eval{kind}.json"
        cmd = [planeloc, "eval", "--gt", poses, "--est", traj, "--align", "none", *extra,
               "--json", json_path]
        run_measured(cmd, f"{out_prefix}.eval{kind}.log")
        with open(json_path) as f:
            stats = json.load(f)
        result[f"ate{kind}_m"] = stats["ape"]["rmse"]
        result[f"eval{kind}_command"] = command_text(cmd)
        if "kitti_drift" in stats:
            result["t_rel_percent"] = stats["kitti_drift"]["t_rel_percent"]
            result["r_rel_deg_per_100m"] = stats["kitti_drift"]["r_rel_deg_per_100m"]
    return result


def run_drive(planeloc, drive, out_dir):
    """The runs of `planeloc run` on one prepared drive, each evaluated."""
    data = os.path.join(ROOT, drive["dir"])
    runs_dir = os.path.join(out_dir, "runs", f"{drive['preset']}-{drive['seed']}")
    os.makedirs(runs_dir, exist_ok=True)
    with open(os.path.join(runs_dir, "lambda1.yaml"), "w") as f:
        f.write(LAMBDA1_SETTINGS)
    poses = os.path.join(data, "sim", "poses", "00.txt")
    records = []
    for name, planes, deterministic, settings in RUNS:
        prefix = os.path.join(runs_dir, name)
        cmd = [planeloc, "run", "--sequence", os.path.join(data, "sim", "sequences", "00"),
               "--init-pose-from", poses]
        cmd += (["--planes", os.path.join(data, "planes.json"), "--init-sigma", "0 0 0"]
                if planes else ["--no-planes"])
        if deterministic:
            cmd.append("--deterministic")
        if settings:
            cmd += ["--config", os.path.join(runs_dir, settings)]
        cmd += ["--out", prefix + ".txt", "--stats", prefix + ".jsonl"]
        print(f"--- {drive['preset']} seed {drive['seed']}: run {name}", flush=True)
        record = {"preset": drive["preset"], "seed": drive["seed"], "run": name,
                  "mode": "planes" if planes else "vo",
                  "threading": "deterministic" if deterministic else "threaded",
                  "lambda": 1.0 if settings else None}
        record.update(run_measured(cmd, prefix + ".log"))
        with open(prefix + ".jsonl.summary.json") as f:
            summary = json.load(f)
        record.update({"frames": summary["frames"], "lost": summary["lost"],
                       "loop_s": summary["seconds"],
                       "fps": summary["frames"] / max(summary["seconds"], 1e-9),
                       "keyframes": summary["keyframes"]})
        record.update(evaluate(planeloc, poses, prefix + ".txt", prefix,
                               drive["path_m"] >= KITTI_MIN_PATH_M))
        records.append(record)
    return records


def read_ate(path):
    """ATE RMSE (m) of a `planeloc eval --json` file."""
    try:
        with open(path) as f:
            return json.load(f)["ape"]["rmse"]
    except (OSError, ValueError, KeyError) as e:
        raise BenchError(f"{rel(path)}: no ATE ({e})") from e


def run_robustness(planeloc, data_dir, prepared, fresh):
    """Issue 10 item 5: ATE with wrong maps per drive, and the ablation. `prepared`: (preset,
    seed) of the drives this run already made or checked (not remade by --fresh again)."""
    scripts = os.path.join(ROOT, "scripts")
    env = {"PLANELOC_BIN": planeloc}
    wrong_maps = []
    for preset, seeds in WRONG_MAP_DRIVES:
        for seed in seeds:
            drive = prepare_drive(planeloc, data_dir, preset, seed,
                                  fresh and (preset, seed) not in prepared)
            prepared.add((preset, seed))
            cmd = [os.path.join(scripts, "bench_wrong_map.sh"), "--preset", preset, "--seeds",
                   str(seed), "--out", data_dir, "--tag", "wrong-map", "--kinds",
                   " ".join(WRONG_MAP_KINDS)]
            print(f"--- {preset} seed {seed}: wrong maps", flush=True)
            record = run_measured(cmd, os.path.join(ROOT, drive["dir"], "wrong-map.log"), env)
            runs = os.path.join(ROOT, drive["dir"], "wrong-map")
            record.update({"preset": preset, "seed": seed, "frames": drive["frames"],
                           "path_m": drive["path_m"],
                           "ate3d_m": {k: read_ate(os.path.join(runs, f"traj_{k}.txt.ate.json"))
                                       for k in WRONG_MAP_KINDS}})
            wrong_maps.append(record)
    preset, seeds = ABLATION_DRIVE
    for seed in seeds:
        if (preset, seed) not in prepared:
            prepare_drive(planeloc, data_dir, preset, seed, fresh)
            prepared.add((preset, seed))
    cmd = [os.path.join(scripts, "bench_ablation.sh"), "--preset", preset, "--seeds",
           " ".join(map(str, seeds)), "--out", data_dir, "--kinds", " ".join(ABLATION_KINDS),
           "--variants", " ".join(ABLATION_VARIANTS)]
    print(f"--- {preset} seeds {seeds}: ablation", flush=True)
    ablation = run_measured(cmd, os.path.join(data_dir, "ablation.log"), env)
    ablation.update({"preset": preset, "seeds": seeds, "kinds": ABLATION_KINDS, "variants": []})
    for variant in ABLATION_VARIANTS:
        with open(os.path.join(data_dir, "ablation", variant + ".yaml")) as f:
            settings = [line.strip() for line in f if line.strip() and not line.startswith("%")]
        ate = {k: [read_ate(os.path.join(data_dir, f"{preset}-{seed}", f"abl-{variant}",
                                         f"traj_{k}.txt.ate.json")) for seed in seeds]
               for k in ABLATION_KINDS}
        ablation["variants"].append({"name": variant, "settings": settings, "ate3d_m": ate})
    return {"kinds": WRONG_MAP_KINDS, "wrong_maps": wrong_maps, "ablation": ablation}


def run_map_lock(planeloc, data_dir, prepared, fresh, presets=None):
    """Issue 30: rows of scripts/bench_map_lock.py over MAP_LOCK_EXACT_DRIVES (exact start) and
    MAP_LOCK_DRAW_DRIVES (draws from the prior); only the drives of `presets` when given."""
    rows = []
    plan = [(preset, seeds, 0, True) for preset, seeds in MAP_LOCK_EXACT_DRIVES]
    plan += [(preset, seeds, MAP_LOCK_DRAWS, False) for preset, seeds in MAP_LOCK_DRAW_DRIVES]
    left_out = sorted({preset for preset, _, _, _ in plan if presets and preset not in presets})
    plan = [step for step in plan if not presets or step[0] in presets]
    for preset, seeds, draws, exact in plan:
        for seed in seeds:
            if (preset, seed) not in prepared:
                prepare_drive(planeloc, data_dir, preset, seed, fresh)
                prepared.add((preset, seed))
        out = os.path.join(data_dir, f"maplock-{preset}-{draws}.json")
        cmd = [sys.executable, os.path.join(ROOT, "scripts", "bench_map_lock.py"), "--planeloc",
               planeloc, "--work", data_dir, "--preset", preset, "--seeds",
               *map(str, seeds), "--draws", str(draws), "--json", out]
        if exact:
            cmd.append("--exact-start")
        print(f"--- {preset} seeds {seeds}: map lock, {draws} draws", flush=True)
        run_measured(cmd, os.path.join(data_dir, f"maplock-{preset}-{draws}.log"))
        with open(out) as f:
            rows += json.load(f)["rows"]
    return {"draws_per_seed": MAP_LOCK_DRAWS, "rows": rows, "presets_left_out": left_out}


def only_map_lock(planeloc, data_dir, out, meta, args):
    """--only-map-lock: maplock.json alone, with the run it comes from."""
    presets = None if args.only_map_lock == "all" else args.only_map_lock.split(",")
    meta["command"] = "scripts/bench_run.py --only-map-lock" + (
        f" {args.only_map_lock}" if presets else "")
    try:
        map_lock = run_map_lock(planeloc, data_dir, set(), args.fresh, presets)
    except BenchError as e:
        print(f"bench_run.py: {e}", file=sys.stderr)
        return 1
    meta["end"] = now_utc()
    map_lock["meta"] = meta
    with open(os.path.join(out, "maplock.json"), "w") as f:
        json.dump(map_lock, f, indent=1)
    print(f"results in {rel(os.path.join(out, 'maplock.json'))}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.environ.get("PLANELOC_BUILD_DIR",
                                                          os.path.join(ROOT, "build")))
    parser.add_argument("--out", help="results folder (default: BUILD/bench)")
    parser.add_argument("--quick", action="store_true", help="tiny drive, filtered benchmarks")
    parser.add_argument("--fresh", action="store_true", help="remake the cached drives")
    parser.add_argument("--no-robustness", action="store_true",
                        help="full mode without the wrong-map and ablation runs (issue 10)")
    parser.add_argument("--no-map-lock", action="store_true",
                        help="full mode without the default-start runs (issue 30)")
    parser.add_argument("--only-map-lock", metavar="PRESETS", nargs="?", const="all",
                        help="only issue 30's default-start runs (maplock.json, with this run's "
                        "date, CPU and commit), on the drives of the comma-separated presets "
                        "(all when none given)")
    parser.add_argument("--drives", type=parse_drives,
                        help='instead of the mode\'s drives, e.g. "small:3,11,21 kitti07-like:1"')
    args = parser.parse_args()
    build = os.path.abspath(args.build)
    out = os.path.abspath(args.out or os.path.join(build, "bench"))
    bin_dir = os.path.join(build, "bin")
    planeloc = os.path.join(bin_dir, "planeloc")
    data_dir = os.path.join(out, "data")
    os.makedirs(out, exist_ok=True)
    if args.only_map_lock:
        if os.path.exists(os.path.join(out, "maplock.json")):
            os.remove(os.path.join(out, "maplock.json"))
        return only_map_lock(planeloc, data_dir, out, machine_and_commit(build, False), args)
    # A failed run leaves no old results behind.
    for stale in ("meta.json", "pipeline.json", "robustness.json", "maplock.json"):
        if os.path.exists(os.path.join(out, stale)):
            os.remove(os.path.join(out, stale))
    shutil.rmtree(os.path.join(out, "gbench"), ignore_errors=True)

    meta = machine_and_commit(build, args.quick)
    plan = args.drives or (QUICK_DRIVES if args.quick else FULL_DRIVES)
    meta["drives"] = [{"preset": p, "seeds": seeds} for p, seeds in plan]
    meta["custom_drives"] = args.drives is not None
    if args.drives:
        meta["command"] += " --drives " + shlex.quote(
            " ".join(f"{p}:{','.join(map(str, seeds))}" for p, seeds in plan))
    started = time.monotonic()
    try:
        drives, runs = [], []
        for preset, seeds in plan:
            for seed in seeds:
                drive = prepare_drive(planeloc, data_dir, preset, seed, args.fresh)
                drives.append(drive)
                runs += run_drive(planeloc, drive, out)
        pipeline = {"drives": drives, "runs": runs}
        robustness = map_lock = None
        prepared = {(d["preset"], d["seed"]) for d in drives}
        if not args.quick and not args.no_robustness:
            robustness = run_robustness(planeloc, data_dir, prepared, args.fresh)
        if not args.quick and not args.no_map_lock:
            map_lock = run_map_lock(planeloc, data_dir, prepared, args.fresh)
        meta["gbench"] = run_gbench(bin_dir, out, args.quick, data_dir)
    except BenchError as e:
        print(f"bench_run.py: {e}", file=sys.stderr)
        return 1
    meta["end"] = now_utc()
    meta["load_end"] = list(os.getloadavg())
    meta["wall_s"] = round(time.monotonic() - started, 1)
    with open(os.path.join(out, "pipeline.json"), "w") as f:
        json.dump(pipeline, f, indent=1)
    if robustness is not None:
        with open(os.path.join(out, "robustness.json"), "w") as f:
            json.dump(robustness, f, indent=1)
    if map_lock is not None:
        with open(os.path.join(out, "maplock.json"), "w") as f:
            json.dump(map_lock, f, indent=1)
    with open(os.path.join(out, "meta.json"), "w") as f:
        json.dump(meta, f, indent=1)
    print(f"results in {rel(out)} ({meta['wall_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
