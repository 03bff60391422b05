"""report.html is self-contained and renders in headless Chromium with no console errors
(Debian ``chromium``; skipped cleanly when it is not installed)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from jointlock.report import Section, render_html
from jointlock.scenario import load_scenario

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--enable-logging=stderr",
    "--v=0",
]


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    from jointlock.run import run_scenario

    out = tmp_path_factory.mktemp("run")
    # 000's own, unconstrained halt-configuration search: its halt breaks limits, so the
    # report's "broken" rendering is exercised too
    sc = load_scenario(
        EXAMPLES / "halt_000.toml",
        {"halt_config.samples": 2000, "halt.n_samples": 101, "halt_config.reachable": False},
    )
    run_scenario(sc).write(out)
    return out / "report.html"


def test_report_is_self_contained(report):
    html = report.read_text()
    assert html.startswith("<!DOCTYPE html>")
    srcs = re.findall(r'(?:src|href)="([^"#]+)"', html)
    assert srcs and all(s.startswith("data:image/png;base64,") for s in srcs)  # no network, no files
    assert "<script" not in html and "http://" not in html and "https://" not in html
    for heading in ("The failure", "Decisions", "Limits kept or broken", "Assumptions and readings"):
        assert heading in html
    assert "INFEASIBLE" in html and "BROKEN" in html  # 000's scenario breaks a limit


def test_cells_are_escaped_and_statuses_coloured():
    html = render_html(
        "t <x>",
        [Section("s", tables=[(["a", "b"], [["<b>", "kept"], [np.float64(np.nan), "BROKEN"]])])],
    )
    assert "&lt;b&gt;" in html and '<span class="ok">kept</span>' in html
    assert '<span class="bad">BROKEN</span>' in html and "nan" not in html.lower()


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/system_deps.sh installs it)")
def test_report_renders_in_headless_chromium(report, tmp_path):
    profile = tmp_path / "profile"
    profile.mkdir()
    proc = subprocess.run(
        [CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--dump-dom", report.as_uri()],
        capture_output=True,
        text=True,
        timeout=90,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    dom = proc.stdout
    assert "<h1>jointlock run:" in dom and dom.count("<img") >= 3 and "Limits kept or broken" in dom
    console = [line for line in proc.stderr.splitlines() if "CONSOLE" in line]
    assert not console, console


def test_a_limit_met_with_no_margin_is_at_the_limit_not_kept():
    """Issue 14, item 3: the report's limits say "at the limit" within 1 % of a limit."""
    from jointlock.report import limit_status

    assert limit_status(39.0, 40.0) == "kept"
    assert limit_status(40.0, 40.0) == limit_status(39.8, 40.0) == "at the limit"
    assert limit_status(40.1, 40.0) == "BROKEN"


def test_the_report_and_the_docs_cite_the_papers(tmp_path):
    """Issue 16, item 6: each seed's title and authors in docs/references.md and in the run
    report of its jobs; 001's reconstruction is in the project's docs."""
    from pathlib import Path

    from jointlock.papers import REFERENCES
    from jointlock.run import run_scenario
    from jointlock.scenario import scenario_from_dict

    docs = Path(__file__).resolve().parents[1] / "docs"
    refs = (docs / "references.md").read_text()
    for seed, text in REFERENCES.items():
        assert text in refs and f"## {seed}" in refs
    assert "global compensation" in (docs / "reconstruction-001.md").read_text()
    sc = scenario_from_dict({"robot": "puma6", "failure": {"joint": 2, "angle_deg": 59.4}, "workspace": {"samples": 2000}})
    run_scenario(sc).write(tmp_path / "o")
    html = (tmp_path / "o" / "report.html").read_text()
    assert "Kinematic Analysis and Fault-Tolerant Trajectory Planning" in html and "Halt Optimization" not in html
