"""report.html is self-contained and renders in headless Chromium with no console errors, its
3-D view drawn and animated (Debian ``chromium``; skipped cleanly when it is not installed)."""

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
    "--enable-unsafe-swiftshader",  # WebGL in software (no GPU here); the page is our own file
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
    # 000's own, unconstrained halt-configuration search (no reachability, no clearance): its
    # halt breaks limits, so the report's "broken" rendering is exercised too
    sc = load_scenario(
        EXAMPLES / "halt_000.toml",
        {
            "halt_config.samples": 2000,
            "halt.n_samples": 101,
            "halt_config.reachable": False,
            "limits.check_clearance": False,
        },
    )
    run_scenario(sc).write(out)
    return out / "report.html"


#: Chromium's own performance hints, logged as console lines on any WebGL page drawn in
#: software; not messages of the page.
BENIGN_CONSOLE = ("GPU stall due to ReadPixels", "Canvas2D: Multiple readback operations")


def _page_only(html: str) -> str:
    """The page without the vendored plotly.js (whose text names its own web sites)."""
    return re.sub(r"<script>.*?</script>", "<script></script>", html, flags=re.S)


def test_report_is_self_contained(report):
    html = report.read_text()
    assert html.startswith("<!DOCTYPE html>")
    page = _page_only(html)
    srcs = re.findall(r'(?:src|href)="([^"#]+)"', page)
    assert srcs and all(s.startswith("data:image/png;base64,") for s in srcs)  # no network, no files
    assert "<script src" not in html and html.count("Plotly.newPlot(") == 1  # one view, the library inline
    assert "http://" not in page and "https://" not in page
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
    console = [
        line for line in proc.stderr.splitlines() if "CONSOLE" in line and not any(b in line for b in BENIGN_CONSOLE)
    ]
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


#: Every example scenario, made quick (the browser checks the page, not the numbers).
EXAMPLE_OVERRIDES = {
    "halt_000": {"halt_config.samples": 2000, "halt.n_samples": 101},
    "jump_001": {"jump.sweep": 6},
    "replan_002": {"workspace.samples": 5000},
    "singular_004": {"singular.samples": 100},
}
ANIMATED = {"halt_000": 1, "jump_001": 1, "replan_002": 1, "singular_004": 0}


@pytest.fixture(scope="module", params=sorted(EXAMPLE_OVERRIDES))
def example_report(request, tmp_path_factory) -> tuple[str, Path]:
    from jointlock.run import run_scenario

    name = request.param
    out = tmp_path_factory.mktemp(name)
    run_scenario(load_scenario(EXAMPLES / f"{name}.toml", EXAMPLE_OVERRIDES[name])).write(out)
    return name, out / "report.html"


def _chromium(url: str, profile: Path, *extra: str) -> subprocess.CompletedProcess:
    profile.mkdir(exist_ok=True)
    return subprocess.run(
        [CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--window-size=1000,700", *extra, url],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_every_example_report_is_under_5_mb_with_its_animation(example_report):
    name, report = example_report
    html = report.read_text()
    assert report.stat().st_size < 5_000_000, report.stat().st_size
    assert html.count('class="jl-animation"') == ANIMATED[name]
    assert ("<script>" in html) == bool(ANIMATED[name])  # no library on a page without a view
    if ANIMATED[name]:
        assert (report.parent / name.split("_")[0] / "motion.json").is_file()


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/system_deps.sh installs it)")
def test_every_example_report_plays_in_headless_chromium(example_report, tmp_path):
    """Issue 16: no console message, the 3-D view drawn (a canvas in it) and its animation
    advancing (``#jl-play`` plays it; the view's data-frame names the frame shown)."""
    name, report = example_report
    proc = _chromium(report.as_uri() + "#jl-play", tmp_path / "p", "--virtual-time-budget=15000", "--dump-dom")
    assert proc.returncode == 0, proc.stderr[-2000:]
    console = [
        line for line in proc.stderr.splitlines() if "CONSOLE" in line and not any(b in line for b in BENIGN_CONSOLE)
    ]
    assert not console, console
    views = re.findall(r'<div class="jl-animation[^"]*"[^>]*>', proc.stdout)
    assert len(views) == ANIMATED[name]
    for view in views:
        frame = re.search(r'data-frame="(\d+)"', view)
        assert frame is not None and int(frame.group(1)) > 0, view  # it played past the first frame
        assert "js-plotly-plot" in view
    if ANIMATED[name]:
        assert "<canvas" in proc.stdout


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (scripts/system_deps.sh installs it)")
def test_the_3d_view_is_drawn_and_moves(tmp_path):
    """Screenshots of a standalone view at its first and last frames: the arm is drawn (many
    pixels neither white nor grey grid) and it moved between them."""
    import matplotlib.image as mpimg

    import jointlock as jl
    from jointlock.plots.animation import write_animation_html
    from jointlock.plots.motion import ArmMotion

    t = np.linspace(0.0, 4.0, 41)
    q = np.outer(t / 4.0, np.radians([90.0, -40.0, 60.0, 0.0, 45.0, 0.0]))
    page = write_animation_html(tmp_path / "v.html", jl.load_robot("puma6"), ArmMotion("moving", t, q, ((4, 0.0),)))
    shots = []
    for frame in (0, 40):
        png = tmp_path / f"f{frame}.png"
        proc = _chromium(page.as_uri() + f"#jl-frame={frame}", tmp_path / f"p{frame}", "--virtual-time-budget=8000", f"--screenshot={png}")
        assert proc.returncode == 0 and png.is_file(), proc.stderr[-2000:]
        rgb = mpimg.imread(png)[..., :3]
        shots.append(rgb)
        coloured = (rgb.max(axis=-1) - rgb.min(axis=-1)) > 0.25  # the arm's blue, the lock's red
        assert coloured.sum() > 500, coloured.sum()
    assert np.abs(shots[0] - shots[1]).max(axis=-1).astype(bool).sum() > 500


def test_every_example_report_has_no_empty_section_and_no_repeated_note(example_report):
    """Issue 16, item 2: every heading has something under it; no note twice."""
    _, report = example_report
    page = _page_only(report.read_text())
    parts = re.split(r"(<h[2-4][^>]*>.*?</h[2-4]>)", page)
    empty = [parts[i] for i in range(1, len(parts) - 1, 2) if not re.sub(r"\s", "", parts[i + 1])]
    assert not empty, empty
    notes = re.findall(r"<li>(.*?)</li>", page)
    assert len(notes) == len(set(notes)), [n for n in set(notes) if notes.count(n) > 1]
    assert " at at " not in page and not re.search(r"\(-[\d.]+ % (lower|higher)\)", page)  # signs in words


@pytest.mark.parametrize("example_report", ["singular_004"], indirect=True)
def test_the_singularity_report_writes_the_conditions_out_and_plots_them(example_report):
    _, report = example_report
    page = report.read_text()
    assert "S2 = 0 and d C3 + e C34 + h S345 = 0" in page and "equations (004 eq. 30)" in page
    assert "sigma_min on each of 004" in page
    assert (report.parent / "figures" / "singular_conditions.svg").is_file()


def test_every_figure_of_every_example_is_also_svg(example_report):
    """Issue 16, item 2: each PNG a run writes has an SVG beside it, a well-formed document
    under 2 MB (dense scatters drawn as an image inside it)."""
    import xml.etree.ElementTree as ET

    _, report = example_report
    pngs = sorted(report.parent.rglob("*.png"))
    assert pngs
    for png in pngs:
        svg = png.with_suffix(".svg")
        assert svg.is_file(), svg
        assert ET.parse(svg).getroot().tag.endswith("svg")
        assert svg.stat().st_size < 2_000_000, (svg, svg.stat().st_size)


def test_svg_figures_are_reproducible(tmp_path):
    from jointlock.io.files import write_figure
    from jointlock.plots._common import offscreen_figure

    fig = offscreen_figure((4, 3))
    ax = fig.add_subplot()
    ax.plot([0, 1], [1, 0])
    ax.scatter(*np.random.default_rng(0).normal(size=(2, 5000)), s=1)
    assert write_figure(fig, tmp_path / "a", "f.png") == ["f.png", "f.svg"]
    write_figure(fig, tmp_path / "b", "f.png")
    first = (tmp_path / "a" / "f.svg").read_bytes()
    assert first == (tmp_path / "b" / "f.svg").read_bytes()
    assert b"<image" in first  # the 5000 points rasterized, the line and axes vector
