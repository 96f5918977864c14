#!/usr/bin/env bash
# `planeloc eval --plot` (issue 12): the legend says "aligned" only when --align aligned, and
# --also-est puts more estimates in the same plot without changing the table on stdout.
# A stand-in tools/plot_trajectory.py (PLANELOC_TOOLS_DIR) records the arguments planeloc passes;
# the real script draws one plot with two estimates when matplotlib is there.
# Usage: tests/eval_plot_test.sh PLANELOC_BINARY SOURCE_DIR
set -uo pipefail
planeloc="$1"
src="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail=0
check() {  # check DESCRIPTION COMMAND...
  local what="$1"; shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fail=1; fi
}

# GT on a curve in x-z (an SE(3) alignment needs more than a line); two estimates off by 0.1 m
# and 0.3 m in x.
poses() {  # poses X_OFFSET
  awk -v dx="$1" 'BEGIN { for (i = 0; i < 20; ++i) printf "1 0 0 %.6f 0 1 0 0 0 0 1 %d\n", 2 * sin(i / 3) + dx, i }'
}
poses 0 >"$tmp/gt.txt"
poses 0.1 >"$tmp/a.txt"
poses 0.3 >"$tmp/b.txt"

mkdir -p "$tmp/tools"
cat >"$tmp/tools/plot_trajectory.py" <<'EOF'
import sys
args = sys.argv[1:]
with open(args[args.index("--out") + 1], "w") as out:
    out.write("\n".join(args) + "\n")
EOF

"$planeloc" eval --gt "$tmp/gt.txt" --est "$tmp/a.txt" --also-est "$tmp/b.txt" \
  >"$tmp/no_plot.out" 2>"$tmp/no_plot.err"
check "--also-est without --plot is exit 2" test $? -eq 2
check "... naming --also-est and the fix" grep -q -- "--also-est.*--plot" "$tmp/no_plot.err"

PLANELOC_TOOLS_DIR="$tmp/tools" "$planeloc" eval --gt "$tmp/gt.txt" --est "$tmp/a.txt" \
  --align none --plot "$tmp/none.png" >"$tmp/none.out" 2>&1
check "eval --align none --plot exits 0" test $? -eq 0
check "--align none: the legend does not say aligned" bash -c "! grep -q aligned '$tmp/none.png'"
check "--align none: the legend names the file and the APE" \
  grep -q "^a.txt, APE rmse 0.100 m$" "$tmp/none.png"

PLANELOC_TOOLS_DIR="$tmp/tools" "$planeloc" eval --gt "$tmp/gt.txt" --est "$tmp/a.txt" \
  --align se3 --also-est "$tmp/b.txt" --plot "$tmp/se3.png" >"$tmp/se3.out" 2>"$tmp/se3.err"
check "eval --align se3 --also-est --plot exits 0" test $? -eq 0
check "--align se3: both legends say aligned se3" \
  test "$(grep -c "(aligned se3)" "$tmp/se3.png")" -eq 2
check "two CSVs handed to the plot" test "$(grep -c "^--csv$" "$tmp/se3.png")" -eq 2
check "the --also-est APE is logged" grep -q -- "--also-est .*b.txt: APE rmse" "$tmp/se3.err"
"$planeloc" eval --gt "$tmp/gt.txt" --est "$tmp/a.txt" --align se3 >"$tmp/se3_alone.out" 2>/dev/null
check "stdout table unchanged by --also-est" cmp -s "$tmp/se3.out" "$tmp/se3_alone.out"

# The real script, when matplotlib is importable: one PNG with both estimates.
if /usr/bin/python3 -c "import matplotlib" 2>/dev/null || python3 -c "import matplotlib" 2>/dev/null; then
  PLANELOC_TOOLS_DIR="$src/tools" "$planeloc" eval --gt "$tmp/gt.txt" --est "$tmp/a.txt" \
    --also-est "$tmp/b.txt" --plot "$tmp/real.png" >/dev/null 2>"$tmp/real.err"
  check "real plot with two estimates written" test -s "$tmp/real.png"
  check "... as a PNG" bash -c "head -c 8 '$tmp/real.png' | grep -q PNG"
else
  echo "skip the real plot: matplotlib is not installed"
fi
exit "$fail"
