"""Figures drawn once for their PNG and once for their SVG (issue 13): the same extent and
pixels as ``savefig(bbox_inches="tight")``, the figure left as it was."""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from jointlock.io._render import render_png, render_svg
from jointlock.io.files import PNG_DPI, figure_files
from jointlock.plots._common import offscreen_figure


def _image(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"))


def _savefig_png(fig, **kw) -> np.ndarray:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=PNG_DPI, **kw)
    return _image(buf.getvalue())


def _best_shift_difference(a: np.ndarray, b: np.ndarray, reach: int = 2) -> float:
    """Mean absolute difference [0..1] of two images at their best offset (up to ``reach`` px)."""
    h, w = min(a.shape[0], b.shape[0]) - reach, min(a.shape[1], b.shape[1]) - reach
    return min(
        float(np.abs(a[dy : dy + h - reach, dx : dx + w - reach].astype(int)
                     - b[reach : h, reach : w].astype(int)).mean()) / 255
        for dy in range(2 * reach + 1)
        for dx in range(2 * reach + 1)
    )  # fmt: skip


def _figure(title_y: float = 1.0, *, tight_layout: bool = True):
    fig = offscreen_figure((4, 3))
    ax = fig.add_subplot()
    ax.plot([0, 1], [1, 0], label="line")
    ax.scatter(*np.random.default_rng(0).normal(size=(2, 3000)), s=1)
    ax.set_title("title", y=title_y)
    ax.set_xlabel("x [m]")
    ax.legend()
    if tight_layout:
        fig.tight_layout()
    return fig


@pytest.mark.parametrize(
    "title_y, tight_layout",
    [(1.0, True), (1.0, False), (1.3, True)],  # untight: the x label below the edge; 1.3: the title above
)
def test_the_png_is_savefig_tight_within_two_pixels(title_y, tight_layout):
    fig = _figure(title_y, tight_layout=tight_layout)
    dpi_before, canvas_before = fig.dpi, fig.canvas
    png, box = render_png(fig, PNG_DPI)
    ours, theirs = _image(png), _savefig_png(fig, bbox_inches="tight")
    # whole pixels, rounded outwards: at most a pixel more on each side
    assert abs(ours.shape[0] - theirs.shape[0]) <= 2 and abs(ours.shape[1] - theirs.shape[1]) <= 2
    # the same picture but for the offset of the crop and sub-pixel antialiasing
    assert _best_shift_difference(ours, theirs) < 0.02  # 1.3 % here: the dense scatter antialiased apart
    assert box.width * PNG_DPI == pytest.approx(ours.shape[1], abs=1)
    assert (fig.dpi, fig.canvas) == (dpi_before, canvas_before)


def test_an_opaque_figure_is_written_rgb_and_a_transparent_one_rgba():
    from PIL import Image

    fig = _figure()
    assert Image.open(io.BytesIO(render_png(fig, PNG_DPI)[0])).mode == "RGB"
    fig.patch.set_alpha(0.0)
    assert Image.open(io.BytesIO(render_png(fig, PNG_DPI)[0])).mode == "RGBA"


def test_not_tight_is_the_figure_s_own_size():
    fig = _figure()
    png, box = render_png(fig, PNG_DPI, tight=False)
    assert box is None
    assert _image(png).shape[:2] == (round(3 * PNG_DPI), round(4 * PNG_DPI))
    assert (_image(png) == _savefig_png(fig)).all()


def test_svg_has_the_png_s_extent_and_the_dense_scatter_as_an_image():
    fig = _figure()
    png, svg = figure_files(fig)
    root = ET.fromstring(svg)
    width_pt = float(root.get("width").removesuffix("pt"))
    assert width_pt / 72 * PNG_DPI == pytest.approx(_image(png).shape[1], abs=1.5)
    assert b"<image" in svg  # 3,000 points > SVG_RASTER_POINTS: rasterized
    assert not any(c.get_rasterized() for c in fig.axes[0].collections)  # undone after
    assert render_svg(fig, PNG_DPI, None) == render_svg(fig, PNG_DPI, None)


def test_a_layout_engine_lays_out_once_and_stays():
    fig = offscreen_figure((4, 3))
    fig.set_layout_engine("constrained")
    fig.add_subplot().plot([0, 1])
    engine = fig.get_layout_engine()
    png, svg = figure_files(fig)
    assert fig.get_layout_engine() is engine
    assert ET.fromstring(svg).tag.endswith("svg") and _image(png).size


def test_ticks_computed_once_draw_the_same_bytes_and_are_given_back(monkeypatch):
    """The ticks held fixed while the PNG and the SVG are drawn: the same files as without,
    and each axis gets its own locator and formatter back (shared axes too)."""
    import contextlib

    from matplotlib.ticker import ScalarFormatter

    import jointlock.io._render as render

    def make():
        fig = offscreen_figure((6, 4))
        axes = fig.subplots(2, 2, sharex=True)
        for i, ax in enumerate(axes.flat):
            ax.plot(np.linspace(0, 1e-3, 50), np.sin(np.arange(50) / (i + 2)) * 10 ** (4 * i), label=f"curve {i}")
            ax.set_ylabel("y [m]")
        axes[0, 0].legend()
        fig.tight_layout()
        return fig

    fig = make()
    before = [(a.get_major_locator(), a.get_major_formatter()) for ax in fig.axes for a in (ax.xaxis, ax.yaxis)]
    frozen = render.render_files(fig, PNG_DPI)
    after = [(a.get_major_locator(), a.get_major_formatter()) for ax in fig.axes for a in (ax.xaxis, ax.yaxis)]
    assert all(b[0] is a[0] and b[1] is a[1] for b, a in zip(before, after))
    assert isinstance(fig.axes[3].yaxis.get_major_formatter(), ScalarFormatter)
    monkeypatch.setattr(render, "_frozen_ticks", lambda fig: contextlib.nullcontext())
    assert render.render_files(make(), PNG_DPI) == frozen  # offset texts (1e8, 1e-3) included
