#!/usr/bin/env python3
"""Which failed ctests failed only because LeakSanitizer's own tracer crashed.

Usage: lsan_tracer_crashes.py BUILD_DIR

Reads ctest's Testing/Temporary/LastTest.log and LastTestsFailed.log and prints, one per line,
the failed tests whose output shows the tracer crash (a known LeakSanitizer defect at process
exit, google/sanitizers#1353) and no other fault: no failed GoogleTest case, no AddressSanitizer
or UndefinedBehaviorSanitizer report, no leak report, no timeout. Exit 0 when every failed test
is such a test (scripts/test.sh then reruns them once), 1 when any failed test has another fault
(which no rerun may hide), 2 when the logs are missing.
"""
import pathlib
import re
import sys

TRACER_CRASH = ("Tracer caught signal", "LeakSanitizer has encountered a fatal error")
OTHER_FAULTS = ("[  FAILED  ]", "ERROR: AddressSanitizer", "ERROR: LeakSanitizer",
                "runtime error:", "SUMMARY: UndefinedBehaviorSanitizer", "Test timeout",
                "***Timeout")


def outputs_by_test(log_text):
    """Each test's block of LastTest.log (from its 'N/M Testing: name' line to the next)."""
    blocks = {}
    name = None
    for line in log_text.splitlines():
        match = re.match(r"^\d+/\d+ Testing: (.+)$", line)
        if match:
            name = match.group(1).strip()
            blocks[name] = []
        elif name is not None:
            blocks[name].append(line)
    return {test: "\n".join(lines) for test, lines in blocks.items()}


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    temporary = pathlib.Path(sys.argv[1]) / "Testing" / "Temporary"
    try:
        log_text = (temporary / "LastTest.log").read_text(errors="replace")
        failed_lines = (temporary / "LastTestsFailed.log").read_text().split()
    except OSError as error:
        print(f"lsan_tracer_crashes: {error}", file=sys.stderr)
        return 2
    failed = [line.split(":", 1)[1] for line in failed_lines if ":" in line]
    outputs = outputs_by_test(log_text)
    only_tracer = []
    for test in failed:
        output = outputs.get(test, "")
        if all(s in output for s in TRACER_CRASH) and not any(s in output for s in OTHER_FAULTS):
            only_tracer.append(test)
    for test in only_tracer:
        print(test)
    return 0 if failed and len(only_tracer) == len(failed) else 1


if __name__ == "__main__":
    sys.exit(main())
