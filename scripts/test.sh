#!/usr/bin/env bash
# Every test, the paper reproductions included: creates .venv if needed (with the test
# extra: pytest, ruff, import-linter, mypy, Pinocchio and EAIK as oracles), lints (ruff), checks the
# import layers (lint-imports, contracts in pyproject.toml) and the types (mypy), builds the
# docs (mkdocs --strict), then runs pytest.
set -euo pipefail
source "$(dirname "$0")/_venv.sh" "test"
# CI also installs Debian's chromium for the HTML rendering test (skipped where it is absent).
if [ "${CI:-}" = "true" ]; then bash scripts/system_deps.sh || echo "chromium not installed: the HTML rendering test will skip"; fi
export MPLBACKEND=Agg
.venv/bin/ruff check .
.venv/bin/lint-imports
.venv/bin/mypy
# the documentation site (guides + API reference from the docstrings): a warning fails
site="$(mktemp -d)"; .venv/bin/mkdocs build --strict --quiet --site-dir "$site"; rm -rf "$site"
exec .venv/bin/python -m pytest -q "$@"
