#!/usr/bin/env python3
"""Mutation checks (issue 37 item 1): does the test suite catch a broken mechanism?

Each scripts/mutants/NAME.patch breaks one key mechanism on purpose (its first lines say what and
which tests to run first). One at a time, in a git worktree of the committed HEAD with a build
folder of its own (never the user's build/ nor their working copy), this script applies the
patch, rebuilds incrementally and runs ctest: first the patch's `Tests first:` regex, then, if
nothing failed, the rest of the suite. A mutant is caught when a test fails with it; every test
that caught one is then run once more on the unmutated build, which it must pass (else the
failure was not the mutant's doing). Writes a JSON record and a Markdown table (docs/reliability.md
holds the last one) and exits 1 when a mutant survives, 2 when a patch no longer applies or builds.

Usage: scripts/mutants.sh [--only NAME[,NAME...]] [--all] [--out DIR] [--markdown FILE]
                          [--update-doc] [--report-only]
  --all          run the whole suite for every mutant (all catching tests, not the first only)
  --out          where the worktree, its build and mutants.json go (default build-mutants/)
  --update-doc   rewrite the table in docs/reliability.md (between its mutants markers)
  --report-only  no build or test: the table (and --update-doc) from the last mutants.json
"""
import argparse
import json
import os
import pathlib
import re
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
PATCHES = ROOT / "scripts" / "mutants"
# format.clang_format checks style, not behaviour (a mutant's one-line edit may break it).
EXCLUDE_LABEL = "^format$"


def log(message):
    print(f"mutants: {message}", file=sys.stderr, flush=True)


def run(cmd, cwd=None, log_file=None, check=True):
    with open(log_file, "a") if log_file else open(os.devnull, "w") as out:
        done = subprocess.run(cmd, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, check=False)
    if check and done.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed (exit {done.returncode})"
                           + (f"; see {log_file}" if log_file else ""))
    return done.returncode


def read_patch(path):
    header = {}
    for line in path.read_text().splitlines():
        if line.startswith("--- "):
            break
        key, sep, value = line.partition(":")
        if sep:
            header[key.strip()] = value.strip()
    for key in ("Mutation", "Tests first"):
        if key not in header:
            raise SystemExit(f"mutants: {path}: the header has no '{key}:' line")
    return {"name": path.stem, "patch": path, "what": header["Mutation"],
            "first": header["Tests first"]}


def ctest(build, regex, exclude, log_file, jobs):
    """Runs ctest on the tests matching `regex` and not `exclude`; returns (failed tests, cases)."""
    cmd = ["ctest", "--output-on-failure", "-j", str(jobs), "--timeout", "900", "-LE",
           EXCLUDE_LABEL]
    if regex:
        cmd += ["-R", regex]
    if exclude:
        cmd += ["-E", exclude]
    started = time.time()
    with open(log_file, "a") as out:
        out.write(f"$ {' '.join(cmd)}\n")
        out.flush()
        done = subprocess.run(cmd, cwd=build, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True, check=False)
        out.write(done.stdout)
    if "No tests were found" in done.stdout:
        raise RuntimeError(f"ctest -R '{regex}' matches no test; see {log_file}")
    failed = []
    if "The following tests FAILED:" in done.stdout:
        listing = done.stdout.split("The following tests FAILED:")[-1]
        failed = re.findall(r"^\s*\d+ - (\S+) \(", listing, re.M)
    # gtest cases ("[  FAILED  ] Suite.Case") and the shell tests' "FAIL name" lines.
    # Paths (temporary folders, the build's binaries) say nothing about which check failed.
    shell = {re.sub(r"(?:/[^\s/]+)+/([^\s/]+)", r"\1", m.strip())
             for m in re.findall(r"^FAIL (.+)$", done.stdout, re.M)}
    cases = sorted(set(re.findall(r"^\[  FAILED  \] (\w+\.\w+(?:/\w+)?)", done.stdout, re.M))
                   | shell)
    return failed, cases, time.time() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", default="", help="comma-separated mutant names (default: all)")
    parser.add_argument("--all", action="store_true",
                        help="run the whole suite for every mutant")
    parser.add_argument("--out", default=str(ROOT / "build-mutants"))
    parser.add_argument("--markdown", help="also write the table to this file")
    parser.add_argument("--update-doc", action="store_true",
                        help="rewrite the table in docs/reliability.md")
    parser.add_argument("--report-only", action="store_true",
                        help="write the table from the last mutants.json")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    args = parser.parse_args()
    if args.update_doc and args.only:
        raise SystemExit("mutants: --update-doc writes the whole table: leave out --only")

    mutants = [read_patch(p) for p in sorted(PATCHES.glob("*.patch"))]
    if args.only:
        wanted = set(args.only.split(","))
        unknown = wanted - {m["name"] for m in mutants}
        if unknown:
            raise SystemExit(f"mutants: no such mutant: {', '.join(sorted(unknown))} "
                             f"(see {PATCHES})")
        mutants = [m for m in mutants if m["name"] in wanted]

    out = pathlib.Path(args.out).resolve()
    if args.report_only:
        summary = json.loads((out / "mutants.json").read_text())
        report(summary, args, out)
        return 0
    tree, build = out / "tree", out / "build"
    out.mkdir(parents=True, exist_ok=True)
    log_file = out / "mutants.log"
    log_file.write_text("")
    head = subprocess.check_output(["git", "-C", str(ROOT), "rev-parse", "HEAD"], text=True).strip()
    if not (tree / ".git").exists():
        run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), head],
            log_file=log_file)
    # Only the worktree of our own is reset; the user's working copy is never touched.
    run(["git", "-C", str(tree), "checkout", "-q", "-f", "--detach", head], log_file=log_file)
    run(["git", "-C", str(tree), "clean", "-q", "-fd"], log_file=log_file)
    run(["cmake", "-S", str(tree), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release"],
        log_file=log_file)
    log(f"building HEAD {head[:7]} in {build}")
    run(["cmake", "--build", str(build), "-j", str(args.jobs)], log_file=log_file)

    results = []
    status = 0
    for mutant in mutants:
        started = time.time()
        record = {"name": mutant["name"], "mutation": mutant["what"], "caught": False,
                  "tests": [], "cases": []}
        if run(["git", "-C", str(tree), "apply", str(mutant["patch"])], log_file=log_file,
               check=False) != 0:
            record["error"] = "the patch no longer applies to HEAD: update it"
            status = 2
        else:
            try:
                log(f"{mutant['name']}: building")
                run(["cmake", "--build", str(build), "-j", str(args.jobs)], log_file=log_file)
                log(f"{mutant['name']}: ctest -R '{mutant['first']}'")
                failed, cases, _ = ctest(build, mutant["first"], None, log_file, args.jobs)
                if not failed or args.all:
                    log(f"{mutant['name']}: the rest of the suite")
                    more, more_cases, _ = ctest(build, None, mutant["first"], log_file, args.jobs)
                    failed, cases = failed + more, sorted(set(cases) | set(more_cases))
                record.update(caught=bool(failed), tests=failed, cases=cases)
            except RuntimeError as error:
                record["error"] = f"the mutant does not build: {error}"
                status = 2
            finally:
                run(["git", "-C", str(tree), "checkout", "-q", "-f", "--", "."], log_file=log_file)
        record["seconds"] = round(time.time() - started)
        log(f"{mutant['name']}: " + (record.get("error") or (
            "caught by " + ", ".join(record["tests"]) if record["caught"] else "SURVIVED")))
        results.append(record)

    # A test that failed on a mutant must pass without it.
    catchers = sorted({t for r in results for t in r["tests"]})
    baseline_failed = []
    if catchers:
        log("unmutated build: the tests that caught a mutant")
        run(["cmake", "--build", str(build), "-j", str(args.jobs)], log_file=log_file)
        regex = "|".join(f"^{re.escape(t)}$" for t in catchers)
        baseline_failed, _, _ = ctest(build, regex, None, log_file, args.jobs)
        for record in results:
            if set(record["tests"]) & set(baseline_failed):
                record["caught"] = False
                record["error"] = ("a catching test fails without the mutant too: "
                                   + ", ".join(sorted(set(record["tests"]) & set(baseline_failed))))
                status = max(status, 2)
    survived = [r["name"] for r in results if not r["caught"] and "error" not in r]
    if survived:
        status = max(status, 1)

    summary = {"head": head, "date": time.strftime("%Y-%m-%d"), "mutants": results,
               "baseline_failed": baseline_failed, "all": args.all}
    (out / "mutants.json").write_text(json.dumps(summary, indent=2) + "\n")
    report(summary, args, out)
    return status


def report(summary, args, out):
    results, head = summary["mutants"], summary["head"]
    table = ["| mutant | mutation | caught by (ctest test: failing cases) | s |",
             "|---|---|---|---:|"]
    for r in results:
        verdict = r.get("error") or ((", ".join(r["tests"]) + (": " + ", ".join(r["cases"])
                                                                if r["cases"] else ""))
                                     if r["caught"] else "**survived**")
        table.append(f"| {r['name']} | {r['mutation']} | {verdict} | {r['seconds']} |")
    text = "\n".join(table) + "\n"
    print(text)
    if args.markdown:
        pathlib.Path(args.markdown).write_text(text)
    if args.update_doc:
        doc = ROOT / "docs" / "reliability.md"
        begin, end = "<!-- mutants:begin -->\n", "<!-- mutants:end -->\n"
        page = doc.read_text()
        if begin not in page or end not in page:
            raise SystemExit(f"mutants: {doc} has no '{begin.strip()}' ... '{end.strip()}' markers")
        stamp = (f"Measured {summary['date']} on {head[:7]} (`scripts/mutants.sh"
                 f"{' --all' if summary.get('all') else ''}`; {sum(r['caught'] for r in results)} of "
                 f"{len(results)} caught).\n\n")
        page = page[:page.index(begin) + len(begin)] + stamp + text + page[page.index(end):]
        doc.write_text(page)
    log(f"{sum(r['caught'] for r in results)} of {len(results)} caught; {out / 'mutants.json'}")


if __name__ == "__main__":
    sys.exit(main())
