#!/usr/bin/env bash
# Every test, the paper reproductions included: creates .venv if needed (with the test
# extra: pytest, ruff, import-linter, mypy, Pinocchio and EAIK as oracles), lints (ruff), checks the
# import layers (lint-imports, contracts in pyproject.toml) and the types (mypy), then runs pytest.
set -euo pipefail
source "$(dirname "$0")/_venv.sh" "test"
# CI also installs Debian's chromium for the HTML rendering test (skipped where it is absent).
if [ "${CI:-}" = "true" ]; then bash scripts/system_deps.sh || echo "chromium not installed: the HTML rendering test will skip"; fi
export MPLBACKEND=Agg
.venv/bin/ruff check .
.venv/bin/lint-imports
.venv/bin/mypy
exec .venv/bin/python -m pytest -q "$@"
