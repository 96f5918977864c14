# Sourced by scripts/test.sh --sanitize and scripts/fuzz.sh: run-time options of the sanitizers.
# Every report is fatal (a test or fuzz run fails on it); third-party findings are suppressed only
# in scripts/lsan.supp and scripts/ubsan.supp, each entry with its reason.
_planeloc_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# check_initialization_order: static-init order bugs across translation units (the CLI's
# CommandRegistrar objects rely on the registry being constructed first).
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1:check_initialization_order=1:strict_init_order=1"
export LSAN_OPTIONS="${LSAN_OPTIONS:+$LSAN_OPTIONS:}suppressions=$_planeloc_root/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:+$UBSAN_OPTIONS:}print_stacktrace=1:halt_on_error=1:suppressions=$_planeloc_root/scripts/ubsan.supp"
unset _planeloc_root
