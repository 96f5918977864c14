"""The section "Same run as ORB-SLAM2 (issue 33)" of docs/benchmarks.md, from the peers.json of
scripts/bench_peers.py: per drive, ORB-SLAM2 stereo without loop closing beside planeloc's visual
odometry and plane mode (exact start and default prior), medians and ranges over interleaved
repeats, ratios to ORB-SLAM2 from the same run, and the issue's goals with their status.
"""
from bench_format import code, table

ROW_NAMES = {
    "orbslam2": "ORB-SLAM2 (stereo, no loop closing)",
    "vo": "planeloc VO",
    "planes-exact": "planeloc planes, exact start",
    "planes-prior": "planeloc planes, default prior",
    "planes-realtime": "planeloc planes, --realtime (10 Hz), exact start",
}
LATENCY_GOAL_MS = 100.0  # p99 at the camera's rate
VO_FPS_GOAL = 1.5  # planeloc VO's frame rate / ORB-SLAM2's, at no more ATE
PLANES_ATE_GOAL = 0.5  # plane mode's ATE / ORB-SLAM2's, every drive
RSS_GOAL = 0.5  # peak RSS / ORB-SLAM2's


def spread(summary, field, decimals):
    s = summary.get(field)
    if not s:
        return "—"
    if summary.get("completed", 0) <= 1 or s["min"] == s["max"]:
        return f"{s['median']:.{decimals}f}"
    return f"{s['median']:.{decimals}f} ({s['min']:.{decimals}f}–{s['max']:.{decimals}f})"


def median(summary, field):
    s = summary.get(field)
    return s["median"] if s else None


def ratio_cell(value, reference, goal=None, lower_is_better=True):
    if value is None or not reference:
        return "—"
    r = value / reference
    text = f"{r:.2f}"
    if goal is not None and (r > goal if lower_is_better else r < goal):
        text = f"**{text}**"
    return text


def drive_rows(drive, tag):
    rows = []
    peer = drive["summary"]["orbslam2"]
    for name in ROW_NAMES:
        if name not in drive["summary"]:
            continue
        s = drive["summary"][name]
        ran = f"{s['completed']}/{s['repeats']}"
        if s["failures"]:
            ran += " (" + "; ".join(str(f)[:80] for f in s["failures"]) + ")"
        is_peer = name == "orbslam2"
        goal_ate = PLANES_ATE_GOAL if name.startswith("planes") else (1.0 if name == "vo" else None)
        commands = [r["command"] for r in drive["runs"][name] if r.get("command")]
        rows.append([
            f"{drive['preset']} {drive['seed']}" if is_peer else "",
            ROW_NAMES[name], code(commands[0]) if commands else "—", ran,
            spread(s, "fps", 1),
            "—" if is_peer else ratio_cell(median(s, "fps"), median(peer, "fps"), VO_FPS_GOAL
                                           if name == "vo" else None, lower_is_better=False),
            spread(s, "cpu_ms_per_frame", 1),
            spread(s, "lost", 0),
            spread(s, "ate_none_m", 3),
            spread(s, "ate_se3_m", 3),
            "—" if is_peer else ratio_cell(median(s, "ate_none_m"), median(peer, "ate_none_m"),
                                           goal_ate),
            spread(s, "t_rel_percent", 2),
            spread(s, "r_rel_deg_per_100m", 3),
            spread(s, "latency_p50_ms", 0) + " / " + spread(s, "latency_p99_ms", 0)
            if s.get("latency_p99_ms") else "—",
            spread(s, "peak_rss_mb", 0),
            "—" if is_peer else ratio_cell(median(s, "peak_rss_mb"), median(peer, "peak_rss_mb"),
                                           RSS_GOAL),
            tag])
    return rows


def goals(data):
    """One line per goal: met on how many drives."""
    drives = data["drives"]
    n = len(drives)
    # A real drive without ground truth (KITTI raw 0001) counts for speed and memory only.
    n_gt = sum(d.get("ground_truth", True) for d in drives)
    n_planes = sum("planes-exact" in d["summary"] for d in drives)
    vo_fps = vo_ate = planes = rss = latency = latency_ate = n_latency = 0
    for d in drives:
        rt = d["summary"].get("planes-realtime")
        if rt and median(rt, "latency_p99_ms") is not None:
            n_latency += 1
            latency += median(rt, "latency_p99_ms") <= LATENCY_GOAL_MS
            exact = median(d["summary"]["planes-exact"], "ate_none_m")
            latency_ate += bool(exact) and median(rt, "ate_none_m") <= 1.1 * exact
        peer, vo = d["summary"]["orbslam2"], d["summary"]["vo"]
        pf, pa, pr = median(peer, "fps"), median(peer, "ate_none_m"), median(peer, "peak_rss_mb")
        if pf and median(vo, "fps") and median(vo, "fps") >= VO_FPS_GOAL * pf:
            vo_fps += 1
        if pa and median(vo, "ate_none_m") is not None and median(vo, "ate_none_m") <= pa:
            vo_ate += 1
        if pa and "planes-exact" in d["summary"] and all(
                median(d["summary"][k], "ate_none_m") is not None and
                median(d["summary"][k], "ate_none_m") <= PLANES_ATE_GOAL * pa
                for k in ("planes-exact", "planes-prior")):
            planes += 1
        if pr and all(median(d["summary"][k], "peak_rss_mb") is not None and
                      median(d["summary"][k], "peak_rss_mb") <= RSS_GOAL * pr
                      for k in ("vo", "planes-exact", "planes-prior") if k in d["summary"]):
            rss += 1
    return [
        f"- planeloc VO ≥ {VO_FPS_GOAL}× ORB-SLAM2's frame rate: {vo_fps} of {n} drives; at or "
        f"below its ATE: {vo_ate} of {n_gt} (drives with ground truth).",
        f"- plane mode ≤ {PLANES_ATE_GOAL}× ORB-SLAM2's ATE (no alignment), exact start and default "
        f"prior: {planes} of {n_planes} drives.",
        f"- peak RSS ≤ {RSS_GOAL}× ORB-SLAM2's, every planeloc row: {rss} of {n} drives.",
        f"- p99 latency ≤ {LATENCY_GOAL_MS:.0f} ms at 10 Hz (plane mode, `--realtime`): "
        f"{latency} of {n_latency} drives; its ATE within 1.1× of the exact start at full speed: "
        f"{latency_ate} of {n_latency}.",
    ]


def section(data, tag):
    peers = data["peers"]
    rows = []
    for drive in peers["drives"]:
        rows += drive_rows(drive, tag)
    return (
        "## Same run as ORB-SLAM2 (issue 33)\n\n"
        f"{code('scripts/bench_peers.sh')} (docs/peers.md): ORB-SLAM2 built from the paper's "
        "baseline source by `scripts/peers/build_orbslam2.sh`, stereo, loop closing never started, "
        "viewer off, frames fed as fast as it takes them, with a **self-trained vocabulary** "
        f"({code(peers.get('vocabulary', '?'))}; the published one is not available), beside "
        "`planeloc run` (threaded) on the same frames. "
        f"{peers.get('repeats', '?')} interleaved rounds per drive; each cell: median (range). "
        "*fps*: frames / the tracking loop's wall time (image decoding included, start-up and "
        "vocabulary loading not). *CPU*: the process's user + system time per frame (start-up "
        "included). *lost*: frames without a pose. *ATE*: RMSE in metres with no alignment "
        "(ORB-SLAM2's poses put into the GT frame by the first GT pose) and with SE(3) "
        "alignment; ORB-SLAM2's are the poses of each frame as tracked, like planeloc's file. "
        "*KITTI drift* on paths of 100 m or more. *ratio*: planeloc / ORB-SLAM2, medians of the "
        "same run (bold: the goal missed). *default prior*: `--init-sigma \"2 0.5 5\"` given the "
        "exact start pose.\n\n"
        + table(["drive", "system", "command (first round)", "runs", "fps", "fps ratio", "CPU (ms/frame)", "lost",
                 "ATE none (m)", "ATE SE(3) (m)", "ATE ratio", "t_rel (%)", "r_rel (°/100 m)",
                 "latency p50 / p99 (ms)", "peak RSS (MB)", "RSS ratio", "measured"], rows)
        + "\n\n**Goals (issue 33):**\n\n" + "\n".join(goals(peers)))
