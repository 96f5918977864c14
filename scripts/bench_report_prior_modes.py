#!/usr/bin/env python3
"""The section "Prior modes in the same run" of docs/benchmarks.md (issue 34 item 4), from the
prior_modes.json of scripts/bench_prior_modes.py: per drive and mode the ATE, t_rel, frame rate,
CPU time per frame and peak RSS, the map sizes, and issue 34's goals, each met or not met as the
data says.

scripts/bench_report.py includes it when build/bench/prior_modes.json exists. Run alone with
--splice, it replaces (or adds) this section of an existing docs/benchmarks.md.
"""
import statistics
import sys

from bench_format import num, splice_report_main, table

TITLE = "## Prior modes in the same run: planes, depth, hybrid (issue 34)"
MODES = [("vo", "VO"), ("plane", "planes"), ("kim", "Kim et al."), ("depth", "depth"),
         ("hybrid", "hybrid")]
# Issue 34 item 4's goals.
RURAL_RATIO, FPS_RATIO, SIZE_RATIO = 0.5, 3.0, 1 / 20


def drive_name(d):
    name = f"{d['preset']} {d['seed']}"
    return name + (f" ({d['lighting']} lighting)" if d.get("lighting", "constant") != "constant"
                   else "")


def value(d, mode, key):
    run = d.get("runs", {}).get(mode, {})
    return None if "error" in run else run.get(key)


def rows_of(drives, key, fmt):
    rows = []
    for d in drives:
        if "error" in d:
            rows.append([drive_name(d), "failed: " + d["error"].replace("|", "\\|")]
                        + ["—"] * (len(MODES) - 1))
            continue
        cells = []
        for mode, _ in MODES:
            run = d["runs"].get(mode, {})
            cells.append("failed" if "error" in run else fmt(run.get(key)))
        rows.append([drive_name(d)] + cells)
    return rows


def goals(drives):
    ok = [d for d in drives if "error" not in d]
    rows = []
    better = [d for d in ok if None not in (value(d, "hybrid", "ate3d_m"), value(d, "plane", "ate3d_m"),
                                          value(d, "depth", "ate3d_m"))]
    met = [d for d in better if value(d, "hybrid", "ate3d_m")
           <= min(value(d, "plane", "ate3d_m"), value(d, "depth", "ate3d_m"))]
    rows.append(["hybrid ATE ≤ min(planes, depth) on every drive",
                 f"{len(met)} of {len(better)} drives",
                 "met" if better and len(met) == len(better) else "not met"])
    rural = [d for d in ok if d["preset"] == "rural"]
    for mode in ("hybrid", "depth"):
        ratios = [value(d, mode, "ate3d_m") / value(d, "vo", "ate3d_m") for d in rural
                  if value(d, mode, "ate3d_m") is not None and value(d, "vo", "ate3d_m")]
        rows.append([f"rural drives: {mode} ATE ≤ {RURAL_RATIO}× VO",
                     ", ".join(f"{r:.2f}" for r in ratios) or "—",
                     "met" if ratios and max(ratios) <= RURAL_RATIO and len(ratios) == len(rural)
                     else "not met"])
    fps = [value(d, "plane", "fps") / value(d, "depth", "fps") for d in ok
           if value(d, "plane", "fps") and value(d, "depth", "fps")]
    rows.append([f"plane mode ≥ {FPS_RATIO:.0f}× depth mode's frame rate",
                 f"median {statistics.median(fps):.2f}× ({min(fps):.2f}–{max(fps):.2f})"
                 if fps else "—",
                 "met" if fps and min(fps) >= FPS_RATIO else "not met"])
    sizes = [d["planes_json_mb"] / d["map_cloud_mb"] for d in ok if d.get("map_cloud_mb")]
    rows.append(["planes.json ≤ 1/20 of the map cloud's size",
                 f"1/{1 / max(sizes):.0f} at worst" if sizes else "—",
                 "met" if sizes and max(sizes) <= SIZE_RATIO else "not met"])
    return rows


def section(results):
    drives = results["drives"]
    header = ["drive"] + [label for _, label in MODES]
    sizes = [[drive_name(d), num(d.get("planes_json_mb")), num(d.get("map_cloud_mb")),
              f"1/{d['map_cloud_mb'] / d['planes_json_mb']:.0f}"
              if d.get("planes_json_mb") else "—"] for d in drives if "error" not in d]
    kept = [f"{drive_name(d)} ({d['measured']['date']}, {d['measured']['commit']})"
            for d in drives if d.get("measured")]
    kept_text = (" Kept from an earlier run of the script (`--resume`): " + ", ".join(kept) + "."
                 if kept else "")
    return (
        f"{TITLE}\n\n"
        f"Measured {results['date']} at {results['commit']} on {results['cpu']} "
        f"({results['cpus']} logical CPUs) by `{results['command']}`. Every run from the first "
        "ground-truth pose (plane and hybrid mode with `--init-sigma \"0 0 0\"`), threaded (the "
        "default), on the same frames in one session. Modes (docs/depth-prior.md): VO "
        "`--no-planes`; planes `--planes planes.json`; Kim et al. `--map-cloud map.pcd` with "
        "`DepthPrior.windowSurfaces: 0` (the depth-to-map residual in each frame's pose, as the "
        "paper); depth `--map-cloud map.pcd` (and the cloud's flat patches in the window BA); "
        f"hybrid both maps.{kept_text}\n\n"
        "ATE RMSE, no alignment (m):\n\n"
        + table(header, rows_of(drives, "ate3d_m", lambda x: num(x, 3)))
        + "\n\nKITTI t_rel (%, 100–800 m segments; — where the drive is shorter):\n\n"
        + table(header, rows_of(drives, "t_rel_percent", lambda x: num(x, 2)))
        + "\n\nFrames per second of the tracking loop:\n\n"
        + table(header, rows_of(drives, "fps", lambda x: num(x, 1)))
        + "\n\nCPU ms per frame (user + system time of the process over its frames):\n\n"
        + table(header, rows_of(drives, "cpu_ms_per_frame", lambda x: num(x, 0)))
        + "\n\nPeak RSS (MB):\n\n"
        + table(header, rows_of(drives, "peak_rss_mb", lambda x: num(x, 0)))
        + "\n\nThe maps on disk (MB): planes.json against the map cloud (`map build` at 0.1 m, "
        "what `--map-cloud` reads; it voxelizes it to `DepthPrior.voxelSize` 0.2 m when loaded):\n\n"
        + table(["drive", "planes.json", "map.pcd", "ratio"], sizes)
        + "\n\nThe goals of issue 34 item 4, on these data (why a goal is missed: docs/depth-prior.md, "
        "\"The bench's goals\"):\n\n"
        + table(["goal", "measured", "verdict"], goals(drives)))


def main():
    return splice_report_main(__doc__.split("\n\n")[0], "prior_modes.json", "bench_prior_modes.py",
                              TITLE, section, "prior modes")


if __name__ == "__main__":
    sys.exit(main())
