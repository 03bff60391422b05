#!/usr/bin/env bash
# Every test, the paper reproductions included: creates .venv if needed (with the test
# extra: pytest, ruff, Pinocchio as an oracle), lints, then runs pytest.
set -euo pipefail
source "$(dirname "$0")/_venv.sh" "test"
# CI also installs Debian's chromium for the HTML rendering test (skipped where it is absent).
if [ "${CI:-}" = "true" ]; then bash scripts/system_deps.sh || echo "chromium not installed: the HTML rendering test will skip"; fi
export MPLBACKEND=Agg
.venv/bin/ruff check .
exec .venv/bin/python -m pytest -q "$@"
