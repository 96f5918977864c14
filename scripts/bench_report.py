#!/usr/bin/env python3
"""Writes docs/benchmarks.md from the JSON results of scripts/bench_run.py (issue 12 item 4).

Reads RESULTS/meta.json, RESULTS/pipeline.json and RESULTS/gbench/*.json (Google Benchmark
output) and writes the whole page: a header with the run (dates, CPU model, logical CPUs, commit,
load average at start and end, quick or full), then one table per group. Every row carries the
command that measured it, the run it comes from (date, CPU, CPUs, commit), and, where the group
has one, a ratio of its result to a reference measured in the same run:

  speed         ORB vs plain cv::ORB (same budget), tensor voting vs Open3D EstimateNormals (same
                radius), window BA lambda 0.5 vs 1, analytic vs autodiff Jacobians, tracker
                threaded vs deterministic (Google Benchmark programs)
  pipeline      plane mode vs visual odometry frames per second, threaded vs --deterministic
                (frames per second and ATE), LocalBA.lambda 0.5 (default) vs 1 (ATE)
  accuracy      per preset and mode over its seeds: mean, spread and range of ATE RMSE 3-D and 2-D
                and KITTI drift; beside them the paper's KITTI-07 numbers, labelled as reported in
                the paper and not measured here
  wrong maps    issue 10 item 5 (RESULTS/robustness.json, full mode; bench_report_wrong_maps.py;
                number formatting in bench_format.py): per drive, ATE with the plane
                map, its wrong copies, a map from noisy poses, the oracle map and no map; the
                worst wrong map over the clean map (bound 1.5) and over the oracle map; and the
                ablation of the association's settings, each against the defaults
  peers         issue 33 (RESULTS/peers.json, scripts/bench_peers.py; bench_report_peers.py): the
                real ORB-SLAM2 beside planeloc's VO and plane mode on the same drives
  prior_modes   issue 34 (RESULTS/prior_modes.json, scripts/bench_prior_modes.py;
                bench_report_prior_modes.py): VO, planes, Kim et al., depth and hybrid on the same
                drives, with the goals met or not
  room          issue 35 (RESULTS/room.json, scripts/bench_room.py; bench_report_room.py): the
                indoor room preset, VO and plane mode, coarse starts, the goals met or not
  processes     every process of the pipeline: wall time, CPU time, peak RSS
  other         every other Google Benchmark result (no reference)

Ratios are result / reference: below 1 means faster (time), more accurate (error) or slower
(frames per second); each table says which. Nothing is measured here: the page is a pure function
of the JSON, so tests/bench_report_test.py checks it against a fixed fixture.

Usage: scripts/bench_report.py [--results build/bench] [--out docs/benchmarks.md]
"""
import argparse
import glob
import json
import os
import re
import sys

import bench_report_map_lock
import bench_report_peers
import bench_report_live_view
import bench_report_prior_modes
import bench_report_room
import bench_report_wrong_maps
from bench_format import cell, code, mean_or_none, num, ratio, run_tag, spread, table

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The paper's KITTI-07 result (stereo localization in a LiDAR plane map; no loop closing).
PAPER_KITTI07 = {"method_ate_m": 0.564, "orbslam2_ate_m": 0.843}

# Suffixes Google Benchmark appends to a benchmark's name (not its arguments).
_SUFFIX = re.compile(r"/(iterations:\d+|min_time:[\d.]+|repeats:\d+|process_time|real_time|"
                     r"manual_time)")


class ReportError(Exception):
    """Missing or malformed results: the message says which file."""


def bench_key(name):
    """BM_Foo/3/2/iterations:1/process_time -> BM_Foo/3/2."""
    return _SUFFIX.sub("", name)


def load_gbench(results):
    """{program: {key: benchmark entry}} of every gbench/*.json (medians when repeated)."""
    programs = {}
    for path in sorted(glob.glob(os.path.join(results, "gbench", "*.json"))):
        try:
            with open(path) as f:
                data = json.load(f)
        except (OSError, ValueError) as e:
            raise ReportError(f"{path}: {e}") from e
        entries = {}
        for b in data.get("benchmarks", []):
            key = bench_key(b.get("run_name", b["name"]))
            if b.get("run_type") == "aggregate":
                if b.get("aggregate_name") == "median":
                    entries[key] = b
            elif key not in entries:
                entries[key] = b
        programs[os.path.splitext(os.path.basename(path))[0]] = entries
    return programs


def load(results):
    """meta, pipeline and Google Benchmark results of one bench run."""
    out = {}
    for name in ("meta", "pipeline"):
        path = os.path.join(results, name + ".json")
        try:
            with open(path) as f:
                out[name] = json.load(f)
        except (OSError, ValueError) as e:
            raise ReportError(f"{path}: {e} (run scripts/bench.sh first)") from e
    out["gbench"] = load_gbench(results)
    out["results"] = results
    for key, name in (("robustness", "robustness.json"), ("map_lock", "maplock.json"),
                      ("peers", "peers.json"), ("live_view", "live_view.json"),
                      ("room", "room.json"), ("prior_modes", "prior_modes.json")):
        path = os.path.join(results, name)  # full mode only
        out[key] = None
        if os.path.exists(path):
            try:
                with open(path) as f:
                    out[key] = json.load(f)
            except (OSError, ValueError) as e:
                raise ReportError(f"{path}: {e}") from e
    return out


# ---------------------------------------------------------------------------------------------
# Header


def header(meta):
    load_start = " / ".join(f"{x:.2f}" for x in meta["load_start"])
    load_end = " / ".join(f"{x:.2f}" for x in meta["load_end"])
    commit = meta["commit"] + (" with uncommitted changes" if meta.get("dirty") else "")
    if meta.get("commit_subject"):
        commit += f" ({meta['commit_subject']})"
    drives = "; ".join(f"`{d['preset']}` seed{'s' if len(d['seeds']) > 1 else ''} "
                       f"{', '.join(map(str, d['seeds']))}" for d in meta["drives"])
    benchmarks = ("a subset of the benchmarks with short minimum times"
                  if meta["mode"] == "quick" else "every benchmark")
    mode = f"{meta['mode']}: drives {drives}" + (
        " (chosen with --drives, not the mode's)" if meta.get("custom_drives") else "")
    mode += f"; {benchmarks}"
    rows = [
        ["date (UTC)", f"{meta['start']} – {meta['end']}"],
        ["mode", f"{code(meta['command'])}, {mode}"],
        ["CPU", f"{cell(meta['cpu_model'])}, {meta['logical_cpus']} logical CPUs"],
        ["commit", cell(commit)],
        ["build", f"{meta.get('build_type') or '?'}, {code(meta['build_dir'])}"],
        ["load average (1 / 5 / 15 min)", f"start {load_start}; end {load_end}"],
        ["wall time of the measurements", f"{meta['wall_s']:.0f} s"],
    ]
    intro = (
        "# Benchmarks\n\n"
        "<!-- Generated by scripts/bench_report.py from the JSON of scripts/bench.sh: do not edit"
        " by hand. -->\n\n"
        "Generated by `scripts/bench.sh [--quick]`, which builds Release, runs every benchmark and "
        "rewrites this page: **never edit a number here by hand**, rerun the script (JSON results "
        f"in `{meta['build_dir']}/bench/`). Every ratio divides a result by its reference measured "
        "in the same run, on the same machine under the same load. The dated experiment records "
        "of issues 4–15, with their commands, are in [experiments.md](experiments.md).\n\n")
    return intro + table(["run", ""], rows)


# ---------------------------------------------------------------------------------------------
# Google Benchmark pairs


def time_ms(entry, field):
    """cpu_time / real_time of an entry in milliseconds."""
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[entry.get("time_unit", "ns")]
    return entry[field] * scale


def metric(entry, name):
    """(value, text) of one measure of a Google Benchmark entry."""
    if entry.get("error_occurred"):
        return None, "skipped: " + cell(entry.get("error_message", "error"))
    process = "/process_time" in entry.get("name", "")
    if name == "cpu":
        value = time_ms(entry, "cpu_time")
        label = "CPU, all threads" if process else "CPU"
    elif name == "wall":
        value, label = time_ms(entry, "real_time"), "wall"
    elif name == "process_cpu_ms":
        value, label = entry.get(name), "CPU, all threads"
    elif name == "fps":
        return entry.get("fps"), f"{num(entry.get('fps'))} fps"
    elif name.endswith("_deg"):
        label = name[:-4].replace("_err", " error").replace("_", " ")
        return entry.get(name), f"{num(entry.get(name))}° {label}"
    else:
        return entry.get(name), f"{num(entry.get(name))} {name}"
    if value is not None and value < 0.01:
        return value, f"{num(round(value * 1e6, 6))} ns {label}"
    return value, f"{num(value)} ms {label}"


# (what, program, benchmark, reference what, reference benchmark, measure, extra counters, note)
GBENCH_PAIRS = [
    ("ORB extraction (ours), one 1242×375 image, 1 thread, budget 2000 features",
     "features_bench", "BM_OrbExtractOneImage/threads:1",
     "plain `cv::ORB`, same budget, scale factor and levels, 1 thread",
     "BM_CvOrbDetectAndCompute", "process_cpu_ms", ["features"], "time"),
    ("tensor-voting normals (ball + 2 stick passes), street map, 1 cm noise",
     "map_bench", "BM_TensorVotingNormals/1/2",
     "Open3D `EstimateNormals` (PCA), same radius, same map",
     "BM_Open3dEstimateNormals/1", "cpu", ["points", "mean_err_deg"], "time"),
    ("tensor-voting normals (ball + 2 stick passes), street map, 3 cm noise",
     "map_bench", "BM_TensorVotingNormals/3/2",
     "Open3D `EstimateNormals` (PCA), same radius, same map",
     "BM_Open3dEstimateNormals/3", "cpu", ["points", "mean_err_deg"], "time"),
    ("tensor-voting normals, map in Morton order (as `map build` writes it), 3 cm noise",
     "map_bench", "BM_TensorVotingNormalsMortonInput/3",
     "Open3D `EstimateNormals` (PCA), same radius, same map",
     "BM_Open3dEstimateNormals/3", "cpu", ["mean_err_deg"], "time"),
    ("tensor-voting normals: mean angle error at 3 cm noise",
     "map_bench", "BM_TensorVotingNormals/3/2",
     "Open3D `EstimateNormals`, same radius", "BM_Open3dEstimateNormals/3",
     "mean_err_deg", ["crease_err_deg"], "error"),
    ("window BA (`SolveWindowBa`), 10 keyframes × 2000 points, λ = 0.5 (default)",
     "optim_bench", "BM_SolveWindowBa/10/2000/50",
     "the same with λ = 1 (no plane term)", "BM_SolveWindowBa/10/2000/100", "cpu",
     ["observations"], "time"),
    ("stereo residual + Jacobian, analytic pose-only functor",
     "optim_bench", "BM_EvaluateStereoPoseOnlyAnalytic",
     "Ceres autodiff of the full stereo functor", "BM_EvaluateStereoAutodiff", "cpu", [],
     "time"),
    ("tracker on sim `small` (300 frames), 2 threads, local BA in a worker",
     "tracking_bench", "BM_TrackSimSmall/2/0",
     "the same `--deterministic` (local BA in line)", "BM_TrackSimSmall/2/1", "fps",
     ["lost"], "fps"),
    ("tracker on KITTI raw 0001 (108 frames), 2 threads, local BA in a worker",
     "tracking_bench", "BM_TrackKittiRaw0001/2/0",
     "the same `--deterministic` (local BA in line)", "BM_TrackKittiRaw0001/2/1", "fps",
     ["lost"], "fps"),
]

RATIO_MEANING = {"time": "time: < 1 faster", "error": "error: < 1 more accurate",
                 "fps": "frames per second: > 1 faster"}


def gbench_pairs(data, commands, tag):
    rows, used = [], set()
    for what, program, key, ref_what, ref_key, measure, extras, kind in GBENCH_PAIRS:
        entries = data["gbench"].get(program, {})
        if key not in entries or ref_key not in entries:
            continue
        used.update({(program, key), (program, ref_key)})
        value, text = metric(entries[key], measure)
        ref_value, ref_text = metric(entries[ref_key], measure)
        extra = ", ".join(metric(entries[key], e)[1] for e in extras if e in entries[key])
        ref_extra = ", ".join(metric(entries[ref_key], e)[1] for e in extras
                              if e in entries[ref_key])
        rows.append([
            cell(what), code(commands.get(program, program)),
            text + (f" ({extra})" if extra else ""),
            f"{ref_what}: {ref_text}" + (f" ({ref_extra})" if ref_extra else ""),
            f"**{ratio(value, ref_value)}** ({RATIO_MEANING[kind]})", tag])
    return rows, used


def gbench_others(data, commands, used, tag):
    rows = []
    for program, entries in sorted(data["gbench"].items()):
        for key, entry in entries.items():
            if (program, key) in used:
                continue
            if entry.get("error_occurred"):
                result = "skipped: " + cell(entry.get("error_message", "error"))
            else:
                result = f"{metric(entry, 'wall')[1]}, {metric(entry, 'cpu')[1]}"
                counters = [f"{k} {num(v)}" for k, v in sorted(entry.items())
                            if k not in _GBENCH_FIELDS and isinstance(v, (int, float))]
                if counters:
                    result += "; " + ", ".join(counters)
            rows.append([code(key), code(commands.get(program, program)), result, tag])
    return rows


_GBENCH_FIELDS = {"family_index", "per_family_instance_index", "repetitions", "repetition_index",
                  "threads", "iterations", "real_time", "cpu_time"}


# ---------------------------------------------------------------------------------------------
# Pipeline


def by_run(runs, preset, name):
    return [r for r in runs if r["preset"] == preset and r["run"] == name]


def seed_command(run):
    """A run's command with its seed's folder written as <preset>-$SEED."""
    return run["command"].replace(f"{run['preset']}-{run['seed']}", f"{run['preset']}-$SEED")


def seeds_text(runs):
    """'seed 3' or 'seeds 3, 11, 21'."""
    seeds = [str(r["seed"]) for r in runs]
    return ("seed " if len(seeds) == 1 else "seeds ") + ", ".join(seeds)


# (what, run, reference what, reference run, measure, kind)
PIPELINE_PAIRS = [
    ("plane mode, threaded: frames per second", "planes-threaded",
     "visual odometry (`--no-planes`), threaded", "vo-threaded", "fps", "fps"),
    ("plane mode, `--deterministic`: frames per second", "planes-deterministic",
     "visual odometry, `--deterministic`", "vo-deterministic", "fps", "fps"),
    ("plane mode, threaded local BA: frames per second", "planes-threaded",
     "plane mode `--deterministic`", "planes-deterministic", "fps", "fps"),
    ("plane mode, threaded local BA: ATE RMSE 3-D", "planes-threaded",
     "plane mode `--deterministic`", "planes-deterministic", "ate3d_m", "error"),
    ("visual odometry, threaded local BA: ATE RMSE 3-D", "vo-threaded",
     "visual odometry `--deterministic`", "vo-deterministic", "ate3d_m", "error"),
    ("plane mode, window BA λ = 0.5 (default), `--deterministic`: ATE RMSE 3-D",
     "planes-deterministic", "`LocalBA.lambda: 1` (no plane term in the window BA)",
     "planes-lambda1-deterministic", "ate3d_m", "error"),
    ("plane mode vs visual odometry, `--deterministic`: ATE RMSE 3-D", "planes-deterministic",
     "visual odometry, `--deterministic`", "vo-deterministic", "ate3d_m", "error"),
]


def measure_text(value, measure):
    if measure == "fps":
        return f"{num(value)} fps"
    return "—" if value is None else f"{value:.3f} m"


def pipeline_pairs(data, tag):
    runs, rows = data["pipeline"]["runs"], []
    presets = list(dict.fromkeys(d["preset"] for d in data["pipeline"]["drives"]))
    for preset in presets:
        for what, name, ref_what, ref_name, measure, kind in PIPELINE_PAIRS:
            these, refs = by_run(runs, preset, name), by_run(runs, preset, ref_name)
            if not these or not refs:
                continue
            value = mean_or_none([r.get(measure) for r in these])
            ref_value = mean_or_none([r.get(measure) for r in refs])
            over = f"`{preset}`, mean over {seeds_text(these)}"
            commands = (f"{code(seed_command(these[0]))}; reference "
                        f"{code(seed_command(refs[0]))}")
            rows.append([cell(what) + f" ({over})", commands, measure_text(value, measure),
                         f"{ref_what}: {measure_text(ref_value, measure)}",
                         f"**{ratio(value, ref_value)}** ({RATIO_MEANING[kind]})", tag])
    return rows


# (label, run) of the accuracy table; plane rows are divided by the VO row of the same threading.
ACCURACY_RUNS = [
    ("plane map, `--deterministic`", "planes-deterministic", "vo-deterministic"),
    ("plane map, threaded", "planes-threaded", "vo-threaded"),
    ("visual odometry, `--deterministic`", "vo-deterministic", None),
    ("visual odometry, threaded", "vo-threaded", None),
]


def accuracy(data, tag):
    runs, rows = data["pipeline"]["runs"], []
    drives = data["pipeline"]["drives"]
    for preset in dict.fromkeys(d["preset"] for d in drives):
        frames = sorted({d["frames"] for d in drives if d["preset"] == preset})
        path = mean_or_none([d["path_m"] for d in drives if d["preset"] == preset])
        for label, name, ref_name in ACCURACY_RUNS:
            these = by_run(runs, preset, name)
            if not these:
                continue
            ref = mean_or_none([r["ate3d_m"] for r in by_run(runs, preset, ref_name)]
                               ) if ref_name else None
            ate = mean_or_none([r["ate3d_m"] for r in these])
            has_drift = any("t_rel_percent" in r for r in these)
            rows.append([
                f"`{preset}` ({'/'.join(map(str, frames))} frames, {path:.0f} m), "
                f"{seeds_text(these)}", label, code(seed_command(these[0])),
                spread([r["ate3d_m"] for r in these], 3), spread([r["ate2d_m"] for r in these], 3),
                spread([r.get("t_rel_percent") for r in these], 2) if has_drift
                else "— (path < 100 m)",
                spread([r.get("r_rel_deg_per_100m") for r in these], 2) if has_drift else "—",
                f"**{ratio(ate, ref)}**" if ref_name else "(reference)", tag])
    method, orbslam2 = PAPER_KITTI07["method_ate_m"], PAPER_KITTI07["orbslam2_ate_m"]
    rows.append([
        "KITTI odometry 07 (real images and LiDAR)",
        "the paper's method; reference ORB-SLAM2 without loop closing", "—",
        f"{method:.3f} vs {orbslam2:.3f} (ATE RMSE)", "—", "—", "—",
        f"**{method / orbslam2:.2f}**", "reported in the paper, not measured here"])
    return rows


def processes(data, tag):
    rows = []
    for drive in data["pipeline"]["drives"]:
        name = f"`{drive['preset']}` seed {drive['seed']}"
        for step in drive["steps"]:
            cached, step_tag = "", tag
            if step.get("cached"):  # measured when the step ran, by an earlier bench run
                cached = f" (cached: made {step.get('date', '?')} at {step.get('commit', '?')})"
                step_tag = run_tag(dict(data["meta"], start=step.get("date", "?"),
                                        commit=step.get("commit", "?"), dirty=False))
            cpu = step["user_cpu_s"] + step["system_cpu_s"]
            rows.append([f"{name}: {step['step']}{cached}", code(step["command"]),
                         f"{step['wall_s']:.1f}", f"{cpu:.1f}", f"{step['peak_rss_mb']:.0f}", "—",
                         step_tag])
        for run in data["pipeline"]["runs"]:
            if run["preset"] != drive["preset"] or run["seed"] != drive["seed"]:
                continue
            rows.append([f"{name}: run {run['run']} ({run['frames']} frames, {run['lost']} lost)",
                         code(run["command"]), f"{run['wall_s']:.1f}",
                         f"{run['user_cpu_s'] + run['system_cpu_s']:.1f}",
                         f"{run['peak_rss_mb']:.0f}", f"{run['fps']:.1f}", tag])
    return rows


STAGES = ("extract", "track", "local_map", "ba")


def stage_times(results, run):
    """Mean ms per frame of each stage of one run, from its per-frame stats (`--stats`), which
    bench_run.py leaves in <results>/runs/<preset>-<seed>/<run>.jsonl; None when they are not
    there. Crease checks report their own ms on the stats line of the frame that took them."""
    path = os.path.join(results, "runs", f"{run['preset']}-{run['seed']}", run["run"] + ".jsonl")
    if not os.path.exists(path):
        return None
    sums = dict.fromkeys(STAGES, 0.0)
    crease_ms, frames = 0.0, 0
    with open(path) as f:
        for line in f:
            if not line.strip():
                continue
            entry = json.loads(line)
            if "ms" not in entry:
                continue
            frames += 1
            for stage in STAGES:
                sums[stage] += entry["ms"].get(stage, 0.0)
            checks = entry.get("crease_check") or []
            for check in checks if isinstance(checks, list) else [checks]:
                crease_ms += check.get("ms", 0.0)
    if frames == 0:
        return None
    times = {stage: sums[stage] / frames for stage in STAGES}
    times["crease"] = crease_ms / frames
    return times


def stages(data, tag):
    rows = []
    for run in data["pipeline"]["runs"]:
        times = stage_times(data["results"], run)
        if times is None:
            continue
        frames = max(run["frames"], 1)
        wall = 1000.0 * run["loop_s"] / frames
        cpu = 1000.0 * (run["user_cpu_s"] + run["system_cpu_s"]) / frames
        frame_thread = times["track"] + times["local_map"] + times["ba"]
        rows.append([f"`{run['preset']}` seed {run['seed']}: {run['run']}", f"{run['fps']:.1f}",
                     f"{wall:.1f}", f"{cpu:.1f}", f"{times['extract']:.1f}",
                     f"{times['track']:.1f}", f"{times['local_map']:.1f}", f"{times['ba']:.1f}",
                     f"{times['crease']:.1f}", f"{max(wall - frame_thread, 0.0):.1f}", tag])
    return rows


def render(data):
    meta = data["meta"]
    tag = run_tag(meta)
    commands = {g["program"]: g["command"] for g in meta.get("gbench", [])}
    speed_rows, used = gbench_pairs(data, commands, tag)
    parts = [header(meta)]
    parts.append(
        "## Speed against a reference (Google Benchmark)\n\n"
        "Each row and its reference come from the same program run. Time is the process CPU time "
        "(all threads) where the row says so: on a shared machine it is fairer than wall time.\n\n"
        + table(["what", "command", "result", "reference (same run)", "ratio", "measured"],
                speed_rows or [["(no benchmark pair in this run)", "", "", "", "", tag]]))
    parts.append(
        "## Pipeline speed and accuracy against a reference\n\n"
        "`planeloc run` from the ground-truth first pose (`--init-pose-from`, plane mode with "
        "`--init-sigma \"0 0 0\"`: no map lock), evaluated by `planeloc eval --align none`. "
        "Frames per second = frames / the run loop's seconds (`<stats>.summary.json`: image "
        "decoding, tracking, and waiting for the local BA).\n\n"
        + table(["what", "command", "result", "reference (same run)", "ratio", "measured"],
                pipeline_pairs(data, tag)))
    parts.append(
        "## Accuracy over seeds\n\n"
        "ATE RMSE without alignment (the plane map or the first pose fixes the frame), metres: "
        "3-D, and 2-D on the ground plane (`--plane xz`); KITTI drift (`--kitti-drift`, "
        "100–800 m segments: none on paths under 100 m): t_rel %, r_rel °/100 m. Each cell: "
        "mean ± sample standard deviation (min–max) over the seeds. Ratio: ATE 3-D mean of the "
        "plane map / visual odometry's, same threading. The last row is **reported in the paper, "
        "not measured here** (real KITTI 07; our drives are simulated).\n\n"
        + table(["drive", "mode", "command", "ATE 3-D (m)", "ATE 2-D (m)", "t_rel (%)",
                 "r_rel (°/100 m)", "ratio to VO", "measured"], accuracy(data, tag)))
    if data.get("robustness"):
        parts.append(bench_report_wrong_maps.section(data, tag))
    if data.get("map_lock"):
        parts.append(bench_report_map_lock.section(data, tag))
    if data.get("peers"):
        parts.append(bench_report_peers.section(data, tag))
    if data.get("live_view"):
        parts.append(bench_report_live_view.section(data["live_view"]))
    if data.get("room"):
        parts.append(bench_report_room.section(data["room"]))
    if data.get("prior_modes"):
        parts.append(bench_report_prior_modes.section(data["prior_modes"]))
    parts.append(
        "## Processes of the pipeline: time and peak RSS\n\n"
        "Peak RSS: `ru_maxrss` of the process (wait4). Simulator and map steps are cached under "
        "`build/bench/data/` by preset and seed; a cached step shows when and at which commit it "
        "ran.\n\n"
        + table(["process", "command", "wall (s)", "CPU (s)", "peak RSS (MB)", "fps", "measured"],
                processes(data, tag)))
    stage_rows = stages(data, tag)
    if stage_rows:
        parts.append(
            "## Per-frame time by stage\n\n"
            "Means over the frames of each run above, ms per frame, from its per-frame stats "
            "(`--stats`, key `ms`). *wall* and *CPU*: the run loop's seconds and the process's "
            "CPU time (all threads) per frame. *extract*: decoding is not in it; ORB on both "
            "images and stereo matching, in the prefetch of the next frames, off the frame "
            "thread. *track*, *local map*, *BA*: on the frame thread (*BA*: building and "
            "submitting the window, waiting for it; all of it in `--deterministic` runs). "
            "*crease*: the LSD crease checks (inside *BA*, on the frame thread). *rest*: "
            "wall − track − local map − BA, the frame thread waiting for the next frame's "
            "features (and writing the trajectory and stats).\n\n"
            + table(["run", "fps", "wall", "CPU", "extract", "track", "local map", "BA",
                     "crease", "rest", "measured"], stage_rows))
    others = gbench_others(data, commands, used, tag)
    if others:
        parts.append(
            "## Other benchmarks (no reference)\n\n"
            + table(["benchmark", "command", "result", "measured"], others))
    return "\n\n".join(parts) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", default=os.path.join(ROOT, "build", "bench"))
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "benchmarks.md"))
    args = parser.parse_args()
    try:
        text = render(load(args.results))
    except ReportError as e:
        print(f"bench_report.py: {e}", file=sys.stderr)
        return 2
    except (KeyError, TypeError) as e:
        print(f"bench_report.py: malformed results in {args.results}: {e!r}", file=sys.stderr)
        return 2
    with open(args.out, "w") as f:
        f.write(text)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
