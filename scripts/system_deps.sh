#!/usr/bin/env bash
# System packages some tests need: Debian's chromium, for the headless check that report.html
# renders with no console errors (tests/test_report_html.py skips cleanly without it).
# Run as root (CI: the test script calls it when CI=true); does nothing otherwise.
set -euo pipefail

if command -v chromium >/dev/null 2>&1; then
    echo "system_deps: chromium already installed ($(command -v chromium))"
    exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
    echo "system_deps: not root; skipping chromium (report.html browser check will be skipped)" >&2
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "system_deps: no apt-get; skipping chromium" >&2
    exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends chromium
