#!/usr/bin/env bash
# Main job on the built-in default: creates .venv if needed, runs `jointlock demo`,
# writes the report to ./jointlock-demo (or the folder given as first argument).
set -euo pipefail
source "$(dirname "$0")/_venv.sh" ""
export MPLBACKEND=Agg
exec .venv/bin/jointlock demo --out "${1:-jointlock-demo}"
