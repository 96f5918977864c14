#!/usr/bin/env python3
"""Plot for `planeloc eval --plot`: top view of GT and estimates, and APE over time.

Input is one CSV per estimate written by planeloc (header
`time|frame,gt_x,gt_y,gt_z,est_x,est_y,est_z,ape`; the GT is drawn from the first), each with a
legend label (--label, in the same order; the CLI says "aligned" only when it aligned).
Exit codes: 0 ok, 2 bad input, 3 matplotlib missing (the CLI turns 3 into an install hint).
"""
import argparse
import csv
import sys

AXES = {"xz": (0, 2), "xy": (0, 1), "yz": (1, 2)}
NAMES = "xyz"


def read_csv(path):
    with open(path, newline="") as stream:
        reader = csv.reader(stream)
        header = next(reader)
        rows = [[float(v) for v in row] for row in reader if row]
    columns = list(zip(*rows)) if rows else [[] for _ in header]
    return header, {name: list(col) for name, col in zip(header, columns)}


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--csv", required=True, action="append")
    parser.add_argument("--label", action="append", default=[])
    parser.add_argument("--out", required=True)
    parser.add_argument("--plane", choices=sorted(AXES), default="xz")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as error:
        print(f"plot_trajectory.py: matplotlib is not available: {error}", file=sys.stderr)
        return 3
    runs = []
    for path in args.csv:
        try:
            runs.append(read_csv(path))
        except (OSError, ValueError, StopIteration) as error:
            print(f"plot_trajectory.py: cannot read {path}: {error}", file=sys.stderr)
            return 2
    labels = args.label + [f"estimate {i + 1}" for i in range(len(args.label), len(runs))]
    header, data = runs[0]

    a, b = AXES[args.plane]
    fig, (top, err) = plt.subplots(1, 2, figsize=(13, 5.5), gridspec_kw={"width_ratios": [1.1, 1]})
    top.plot(data["gt_" + NAMES[a]], data["gt_" + NAMES[b]], "k--", lw=1.2, label="ground truth")
    for i, ((_, est), label) in enumerate(zip(runs, labels)):
        top.plot(est["est_" + NAMES[a]], est["est_" + NAMES[b]], f"C{i}-", lw=1.2, label=label)
    if data["gt_" + NAMES[a]]:
        top.plot(data["gt_" + NAMES[a]][0], data["gt_" + NAMES[b]][0], "go", label="start")
    top.set_xlabel(f"{NAMES[a]} (m)")
    top.set_ylabel(f"{NAMES[b]} (m)")
    top.set_aspect("equal", adjustable="datalim")
    top.set_title(f"top view ({args.plane})")
    top.grid(True, alpha=0.3)
    top.legend(loc="best")

    time_name = header[0]
    for i, ((est_header, est), label) in enumerate(zip(runs, labels)):
        err.plot(est[est_header[0]], est["ape"], f"C{i}-", lw=1.0, label=label)
    if len(runs) > 1:
        err.legend(loc="best")
    err.set_xlabel("time (s)" if time_name == "time" else "frame")
    err.set_ylabel("APE translation (m)")
    err.set_title("APE over time")
    err.grid(True, alpha=0.3)
    if args.title:
        fig.suptitle(args.title)
    fig.tight_layout()
    try:
        fig.savefig(args.out, dpi=110)
    except OSError as error:
        print(f"plot_trajectory.py: cannot write {args.out}: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
