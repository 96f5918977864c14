#!/usr/bin/env python3
"""The section "Live view" of docs/benchmarks.md (issue 36), from the live_view.json of
scripts/bench_live_view.py: frames per second of one drive without --view, with it and nobody
watching, with a stalled client and with headless Chromium following the page; medians and
ranges over interleaved rounds, each as a ratio to the run without --view of the same rounds.

scripts/bench_report.py includes it when build/bench/live_view.json exists. Run alone with
--splice, it replaces (or adds, before "## Processes of the pipeline") this section of an existing
docs/benchmarks.md, so that the live view's benchmark can be measured without the hour of the
full bench.
"""
import sys

from bench_format import code, splice_report_main, table

TITLE = "## Live view: frame rate while watched (issue 36)"
GOAL = 0.05  # |fps with --view / fps without - 1|
ROW_NAMES = {
    "off": "no `--view`",
    "view": "`--view`, nobody watching",
    "stalled": "`--view`, a client that never reads `/events`",
    "browser": "`--view`, headless Chromium following the page (same 2 cores)",
}


def section(live):
    tag = f"{live['date']}, {live['cpu']}, {live['cpus']} CPUs, {live['commit']}"
    modes = live["modes"]
    reference = modes["off"]["median_fps"]
    rows = []
    for name in ("off", "view", "stalled", "browser"):
        if name not in modes:
            continue
        fps = modes[name]["fps"]
        median = modes[name]["median_fps"]
        change = median / reference - 1
        status = "" if name == "off" else (" (goal met)" if abs(change) < GOAL else
                                           f" (goal: within {GOAL * 100:.0f} %)")
        rows.append([ROW_NAMES[name], f"{median:.1f} ({min(fps):.1f}–{max(fps):.1f})",
                     "—" if name == "off" else f"{change * 100:+.1f} %{status}", tag])
    return (
        f"{TITLE}\n\n"
        f"{code(live['command'])}: {live['drive']}, plane mode from the exact start, at full "
        "speed (no `--realtime`), in "
        f"{live['rounds']} interleaved rounds. fps = frames / the run loop's seconds; median "
        "(min–max) over the rounds; change = median / the median without `--view`. The goal "
        "(issue 36) is a change under 5 % with `--view`; a browser on the same machine also "
        "takes CPU from the run, which is the machine's cost, not the server's. docs/live-view.md "
        "says how the view is decoupled from tracking.\n\n"
        + table(["run", "fps", "change", "measured"], rows))


def main():
    return splice_report_main(__doc__.split("\n\n")[0], "live_view.json", "bench_live_view.py", TITLE, section,
                              "live view")


if __name__ == "__main__":
    sys.exit(main())
