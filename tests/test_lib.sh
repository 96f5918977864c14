# Helpers of the shell tests (report_browser_test.sh, live_view_browser_test.sh, asl_run_test.sh,
# room_run_test.sh):
# sourced after the caller set `tmp` (a scratch folder) and, for `missing`, `skip_what` (what goes
# unchecked when a component is missing). Sets `fail`; require_browser sets `chromium` and
# `python` (the first python3 that imports PIL: a pyenv `python3` on PATH often lacks Debian's
# python3-pil).
fail=0
check() {  # check DESCRIPTION COMMAND...
  local what="$1"; shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fail=1; fi
}
missing() {  # missing WHAT: skip (exit 77), or fail in CI
  if [ "${PLANELOC_REQUIRE_COMPONENTS:-0}" = 1 ]; then
    echo "FAIL $1 is not installed and PLANELOC_REQUIRE_COMPONENTS=1 (fix: ./scripts/setup.sh)"
    exit 1
  fi
  echo "SKIP $1 is not installed (./scripts/setup.sh installs it); $skip_what"
  exit 77
}
run_step() {  # run_step NAME COMMAND...: its output in $tmp/NAME.log, shown when it fails
  local name="$1"; shift
  if ! "$@" >"$tmp/$name.log" 2>&1; then
    echo "FAIL $name"; tail -20 "$tmp/$name.log"; exit 1
  fi
}
require_browser() {  # sets chromium and python, or skips
  chromium="$(command -v chromium || command -v chromium-browser || true)"
  [ -n "$chromium" ] || missing chromium
  python=""
  local candidate
  for candidate in ${PLANELOC_PYTHON:-} python3 /usr/bin/python3; do
    if "$candidate" -c "import PIL" 2>/dev/null; then python="$candidate"; break; fi
  done
  [ -n "$python" ] || missing "python3-pil"
}
find_python() {  # sets python: PLANELOC_PYTHON, else the first python3 on PATH, else Debian's
  python=""
  for candidate in ${PLANELOC_PYTHON:-} python3 /usr/bin/python3; do
    if command -v "$candidate" >/dev/null; then python="$candidate"; break; fi
  done
}
