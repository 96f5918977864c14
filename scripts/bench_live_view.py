#!/usr/bin/env python3
"""Frame rate of `planeloc run` with and without the live view (issue 36 item 1): does watching a
run slow it? Writes live_view.json under --out (build/bench by default).

One drive (a simulated sequence and its plane map, made once under --data), tracked at full
speed (no --realtime) in plane mode from the exact start, in interleaved rounds of:

  off        no --view
  view       --view, nobody connected (server and image drawing only)
  stalled    --view, a client that opens /events and never reads (a browser that hangs: the
             server's writes to it block, the run must not)
  browser    --view, headless Chromium following the page for the whole run (on this machine,
             so it competes with the run for the same cores)

fps = frames / the run loop's seconds (<stats>.summary.json). The section "Live view" of
docs/benchmarks.md is rendered from it by scripts/bench_report_live_view.py.

Usage: scripts/bench_live_view.py [--build build] [--out build/bench] [--rounds 3]
                                  [--preset tiny] [--seed 1] [--frames 1200]
A drive of 1200 frames (about 27 s at full speed) amortizes the browser's start (parsing three.js,
the first render of the map: about 3 s of a core) as a long run does.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

from bench_run import cpu_model, tree_commit

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = ["off", "view", "stalled", "browser"]


def run(cmd, log):
    with open(log, "w") as f:
        subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, check=True)


def prepare(planeloc, data, preset, seed, frames):
    os.makedirs(data, exist_ok=True)
    seq = os.path.join(data, "sim", "sequences", "00")
    poses = os.path.join(data, "sim", "poses", "00.txt")
    planes = os.path.join(data, "planes.json")
    if not os.path.exists(planes):
        run([planeloc, "sim", "--out", os.path.join(data, "sim"), "--preset", preset, "--seed",
             str(seed), "--frames", str(frames), "--force"], os.path.join(data, "sim.log"))
        run([planeloc, "map", "build", "--sequence", seq, "--poses", poses, "--out",
             os.path.join(data, "map.pcd")], os.path.join(data, "map.log"))
        run([planeloc, "map", "planes", "--map", os.path.join(data, "map.pcd"), "--out", planes],
            os.path.join(data, "planes.log"))
    return seq, poses, planes


def chromium_binary():
    return shutil.which("chromium") or shutil.which("chromium-browser")


def one_run(planeloc, seq, poses, planes, mode, work):
    out = os.path.join(work, f"{mode}.txt")
    stats = os.path.join(work, f"{mode}.jsonl")
    cmd = [planeloc, "run", "--sequence", seq, "--init-pose-from", poses, "--planes", planes,
           "--init-sigma", "0 0 0", "--out", out, "--stats", stats]
    if mode != "off":
        cmd.append("--view")
    log_path = os.path.join(work, f"{mode}.log")
    log = open(log_path, "w")
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
    helper = None
    stalled = None
    if mode != "off":
        url = None
        for _ in range(200):
            with open(log_path) as f:
                m = re.search(r"live view: (http://[0-9.]+:(\d+)/)", f.read())
            if m:
                url, port = m.group(1), int(m.group(2))
                break
            time.sleep(0.02)
        if url is None:
            proc.kill()
            raise RuntimeError(f"no live view address in {log_path}")
        if mode == "stalled":
            stalled = socket.create_connection(("127.0.0.1", port))
            stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            stalled.sendall(b"GET /events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        elif mode == "browser":
            profile = tempfile.mkdtemp(prefix="chromium-")
            helper = subprocess.Popen(
                [chromium_binary(), "--headless", "--no-sandbox", "--disable-gpu",
                 "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--window-size=1400,1100", f"--user-data-dir={profile}", "--no-first-run",
                 "--dump-dom", url + "?settle=120000"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    code = proc.wait()
    log.close()
    if stalled:
        stalled.close()
    if helper:
        helper.kill()
        helper.wait()
    if code != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {code} (log {log_path})")
    with open(stats + ".summary.json") as f:
        summary = json.load(f)
    return {"fps": summary["frames"] / summary["seconds"], "seconds": summary["seconds"],
            "frames": summary["frames"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--out", default=None)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--preset", default="tiny")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--frames", type=int, default=1200)
    args = parser.parse_args()
    out = args.out or os.path.join(args.build, "bench")
    planeloc = os.path.join(args.build, "bin", "planeloc")
    commit = tree_commit("+")
    modes = MODES if chromium_binary() else [m for m in MODES if m != "browser"]
    data = os.path.join(out, "data", f"live-{args.preset}-{args.seed}-{args.frames}")
    seq, poses, planes = prepare(planeloc, data, args.preset, args.seed, args.frames)
    work = os.path.join(out, "runs", "live-view")
    os.makedirs(work, exist_ok=True)
    rows = {m: [] for m in modes}
    for r in range(args.rounds):
        for m in modes:
            rows[m].append(one_run(planeloc, seq, poses, planes, m, work))
            print(f"round {r + 1}/{args.rounds} {m}: {rows[m][-1]['fps']:.1f} fps", flush=True)
    result = {
        "date": datetime.date.today().isoformat(), "commit": commit, "cpu": cpu_model(),
        "cpus": os.cpu_count(), "host": platform.node(), "rounds": args.rounds,
        "drive": f"{args.preset} seed {args.seed}, {args.frames} frames",
        "command": f"scripts/bench_live_view.py --preset {args.preset} --seed {args.seed} "
                   f"--frames {args.frames} --rounds {args.rounds}",
        "modes": {m: {"fps": [x["fps"] for x in rows[m]],
                      "median_fps": statistics.median(x["fps"] for x in rows[m])}
                  for m in modes},
    }
    path = os.path.join(out, "live_view.json")
    with open(path, "w") as f:
        json.dump(result, f, indent=1)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
