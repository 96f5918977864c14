"""Number and Markdown formatting shared by scripts/bench_report.py and its sections."""
import argparse
import json
import math
import os
import re
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def num(x, decimals=None):
    """A number with about three significant digits (or fixed decimals); '—' when missing."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    if decimals is not None:
        return f"{x:.{decimals}f}"
    ax = abs(x)
    if ax >= 100:
        return f"{x:.0f}"
    if ax >= 10:
        return f"{x:.1f}"
    if ax >= 1:
        return f"{x:.2f}"
    return f"{x:.3g}"


def ratio(value, reference):
    if value is None or reference is None or reference == 0:
        return "—"
    return f"{value / reference:.2f}"


def code(text):
    return "`" + text.replace("|", "\\|") + "`"


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def run_tag(meta):
    """The short 'measured' cell every row carries: date, CPU, logical CPUs, commit."""
    dirty = "+" if meta.get("dirty") else ""
    return cell(f"{meta['start'][:10]}, {meta['cpu_model']}, {meta['logical_cpus']} CPUs, "
                f"{meta['commit']}{dirty}")


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def spread(values, decimals):
    """'mean ± sample std (min–max)' of values; the std and range only with two or more."""
    values = [v for v in values if v is not None]
    if not values:
        return "—"
    mean = statistics.fmean(values)
    if len(values) == 1:
        return f"{mean:.{decimals}f}"
    std = statistics.stdev(values)
    return (f"{mean:.{decimals}f} ± {std:.{decimals}f} "
            f"({min(values):.{decimals}f}–{max(values):.{decimals}f})")


def mean_or_none(values):
    values = [v for v in values if v is not None]
    return statistics.fmean(values) if values else None


def splice_section(doc_path, title, text, before="## Processes of the pipeline"):
    """Replaces the section `title` (up to the next "## ") of the page at `doc_path` with `text`,
    or inserts it before the section `before` (at the end when absent)."""
    with open(doc_path) as f:
        doc = f.read()
    pattern = re.compile(re.escape(title) + r".*?(?=\n## |\Z)", re.S)
    if pattern.search(doc):
        doc = pattern.sub(lambda _: text.rstrip("\n") + "\n", doc, count=1)
    else:
        at = doc.find(before)
        if at < 0:
            doc = doc.rstrip("\n") + "\n\n" + text
        else:
            doc = doc[:at] + text.rstrip("\n") + "\n\n" + doc[at:]
    with open(doc_path, "w") as f:
        f.write(doc)


def splice_report_main(description, results_name, producer, title, section, what):
    """The main of a report that renders one section from RESULTS/results_name and splices it into
    docs/benchmarks.md (--splice): 2 with the reason when the results cannot be read."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--results", default=os.path.join(ROOT, "build", "bench"))
    parser.add_argument("--splice", default=os.path.join(ROOT, "docs", "benchmarks.md"))
    args = parser.parse_args()
    path = os.path.join(args.results, results_name)
    try:
        with open(path) as f:
            results = json.load(f)
    except (OSError, ValueError) as e:
        print(f"{os.path.basename(sys.argv[0])}: {path}: {e} (run scripts/{producer} first)",
              file=sys.stderr)
        return 2
    splice_section(args.splice, title, section(results) + "\n")
    print(f"wrote the {what} section of {args.splice}")
    return 0

