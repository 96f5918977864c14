#!/usr/bin/env bash
# Mutation checks (issue 37 item 1): applies each scripts/mutants/*.patch in a worktree of its own,
# rebuilds, runs the suite and says which test caught it (docs/reliability.md, "Mutation checks").
# Runs with the bench (scripts/bench.sh), not in CI. See scripts/mutants.py --help.
set -euo pipefail
exec python3 "$(dirname "${BASH_SOURCE[0]}")/mutants.py" "$@"
