"""One figure, rendered once for its PNG and once for its SVG (issue 13).

``savefig(..., bbox_inches="tight")`` lays the figure out and draws it twice per file (a dry
run to measure the artists' extents, then the real draw): four draws for a PNG and its SVG,
and text layout and tick formatting dominate each.  Here the PNG is drawn once by Agg and
cropped to the box of the pixels drawn (plus ``savefig.pad_inches``); the SVG is then drawn
once inside the same box.  The crop is whole pixels and follows the ink rather than the text
boxes (which include blank ascent and descent), so the images agree with ``savefig``'s to
within a few pixels of margin.  Content reaching the canvas's edge is measured as ``savefig``
measures it.
"""

from __future__ import annotations

import io
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

#: A scatter of more points than this is drawn as an image inside the SVG (axes, labels and
#: lines stay vector): a workspace cloud or 36,000 samples as vector marks would be megabytes.
SVG_RASTER_POINTS = 2000


@contextmanager
def _no_layout_engine(fig: Any) -> Iterator[None]:
    """No layout engine while saving: the layout is already done (by the Agg draw), and an
    engine would make ``savefig`` lay out and draw the figure once more first."""
    engine = fig.get_layout_engine()
    if engine is None:
        yield
        return
    fig.set_layout_engine(None)
    try:
        yield
    finally:
        fig.set_layout_engine(engine)


@contextmanager
def _agg_canvas(fig: Any, dpi: float) -> Iterator[Any]:
    """``fig`` on an Agg canvas at ``dpi``; its own canvas and dpi are given back after (a
    pyplot figure keeps its window)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    old_canvas, old_dpi = fig.canvas, fig.dpi
    canvas = FigureCanvasAgg(fig)  # sets itself as fig.canvas
    fig.dpi = dpi
    try:
        yield canvas
    finally:
        fig.dpi = old_dpi
        fig.set_canvas(old_canvas)


#: zlib level of the PNGs: level 3 encodes in about half the time of Pillow's default 6, and
#: with the alpha channel dropped (below) the files still come out no larger.
PNG_COMPRESS_LEVEL = 3


@contextmanager
def _frozen_ticks(fig: Any) -> Iterator[None]:
    """Each axis's major ticks and labels computed once, as the draw would compute them, and
    held fixed while the figure is drawn (undone after).  A draw asks for them about ten times
    per axis (the axis, its label, the title, the shared axes' boxes), each time running the
    locator and formatting every label again; the drawn figure is the same, byte for byte.
    Only plain 2-D axes of a figure without a layout engine (which would move them in the draw)."""
    from matplotlib.ticker import FixedFormatter, FixedLocator

    undo: list[tuple[Any, Any, Any]] = []
    if fig.get_layout_engine() is None:
        for ax in fig.axes:
            if ax.name != "rectilinear" or ax.get_aspect() != "auto":  # a draw may change their limits
                continue
            for axis in (ax.xaxis, ax.yaxis):
                locator, formatter = axis.get_major_locator(), axis.get_major_formatter()
                locs = list(locator())
                fixed = FixedFormatter(formatter.format_ticks(locs))
                fixed.set_offset_string(formatter.get_offset())
                undo.append((axis, locator, formatter))
                axis.set_major_locator(FixedLocator(locs))
                axis.set_major_formatter(fixed)
    try:
        yield
    finally:
        for axis, locator, formatter in reversed(undo):  # shared axes share one ticker: last set, first undone
            axis.set_major_locator(locator)
            axis.set_major_formatter(formatter)


def _png_bytes(rgba: np.ndarray, dpi: float) -> bytes:
    """PNG of an RGBA pixel array with ``savefig``'s metadata; RGB when every pixel is opaque
    (a figure on its white face: a quarter fewer bytes to compress, the same picture)."""
    import matplotlib
    from PIL import Image, PngImagePlugin

    opaque = bool((rgba[..., 3] == 255).all())
    image = Image.fromarray(np.ascontiguousarray(rgba[..., :3] if opaque else rgba), "RGB" if opaque else "RGBA")
    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/")
    buf = io.BytesIO()
    image.save(buf, format="png", dpi=(dpi, dpi), pnginfo=info, compress_level=PNG_COMPRESS_LEVEL)
    return buf.getvalue()


def _ink_box(rgba: np.ndarray, face: np.ndarray) -> tuple[int, int, int, int] | None:
    """(top, bottom, left, right) [pixel, bottom and right exclusive] of what is drawn on the
    figure's face; None when nothing is, or when the ink reaches the canvas's edge (the content
    may go on beyond it)."""
    ink = (rgba != face).any(axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if rows.size == 0 or rows[0] == 0 or cols[0] == 0 or rows[-1] == ink.shape[0] - 1 or cols[-1] == ink.shape[1] - 1:
        return None
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def render_png(fig: Any, dpi: float, *, tight: bool = True) -> tuple[bytes, Any]:
    """The figure as PNG bytes, drawn once, and the box it was cropped to.

    Parameters
    ----------
    fig
        A :class:`matplotlib.figure.Figure` (left as it was).
    dpi
        Resolution [dots per inch].
    tight
        Crop to the drawn content plus ``savefig.pad_inches`` (as ``bbox_inches="tight"``);
        else the figure's own size.  The content is the box of the pixels drawn (not the
        artists' extents: no second pass over every tick label), unless they reach the
        canvas's edge.

    Returns
    -------
    png : bytes
    bbox : matplotlib.transforms.Bbox or None
        The crop box [inch] (None without ``tight``), to save the SVG of the same extent.
    """
    import matplotlib
    from matplotlib.colors import to_rgba
    from matplotlib.transforms import Bbox

    with _agg_canvas(fig, dpi) as canvas, _frozen_ticks(fig):
        canvas.draw()
        rgba = np.asarray(canvas.buffer_rgba())
        if not tight:
            return _png_bytes(rgba.copy(), dpi), None
        face = np.round(255 * np.asarray(to_rgba(fig.get_facecolor()))).astype(np.uint8)
        ink = _ink_box(rgba, face)
        content = None if ink is not None else fig.get_tightbbox(canvas.get_renderer())
    height, width = rgba.shape[:2]
    if ink is not None:
        top, bottom, left, right = ink
    else:  # ink at the canvas's edge: the artists' own extents say how far it goes
        assert content is not None
        left, right = int(np.floor(content.x0 * dpi)), int(np.ceil(content.x1 * dpi))
        top, bottom = height - int(np.ceil(content.y1 * dpi)), height - int(np.floor(content.y0 * dpi))
        if left < 0 or top < 0 or right > width or bottom > height:
            # drawn content beyond the figure's edge, clipped by the Agg draw: savefig grows the canvas
            box = content.padded(matplotlib.rcParams["savefig.pad_inches"])
            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=dpi, bbox_inches=box, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
            return buf.getvalue(), box
    pad = int(round(matplotlib.rcParams["savefig.pad_inches"] * dpi))
    left, top, right, bottom = left - pad, top - pad, right + pad, bottom + pad
    # the padding may reach past the figure's edge: the figure's face colour there, as savefig
    out = np.empty((bottom - top, right - left, 4), np.uint8)
    out[...] = face
    y0, x0 = max(top, 0), max(left, 0)
    y1, x1 = min(bottom, height), min(right, width)
    out[y0 - top : y1 - top, x0 - left : x1 - left] = rgba[y0:y1, x0:x1]
    # the SVG takes the box of whole pixels the PNG shows, so both have the same extent
    box = Bbox.from_extents(left / dpi, (height - bottom) / dpi, right / dpi, (height - top) / dpi)
    return _png_bytes(out, dpi), box


@contextmanager
def _dense_rasterized(fig: Any) -> Iterator[None]:
    """Scatters of more than :data:`SVG_RASTER_POINTS` points rasterized (undone after)."""
    undo: list[Any] = []
    for ax in fig.axes:
        dense = [a for a in ax.collections if len(getattr(a, "get_offsets", lambda: ())()) > SVG_RASTER_POINTS]
        if dense and ax.name == "3d":  # mplot3d rasterizes by z-order only
            undo.append((ax.set_rasterization_zorder, ax.get_rasterization_zorder()))
            ax.set_rasterization_zorder(max(a.get_zorder() for a in dense) + 0.5)
        for artist in dense if ax.name != "3d" else ():
            undo.append((artist.set_rasterized, artist.get_rasterized()))
            artist.set_rasterized(True)
    try:
        yield
    finally:
        for setter, value in undo:
            setter(value)


def render_svg(fig: Any, dpi: float, bbox: Any | None) -> bytes:
    """The figure as SVG, drawn once: text kept as paths (it renders the same everywhere),
    scatters of more than :data:`SVG_RASTER_POINTS` points rasterized at ``dpi``, cropped to
    ``bbox`` [inch] (None: the figure's own size).  The same figure gives the same bytes."""
    import matplotlib

    buf = io.BytesIO()
    # no date and fixed element ids: the same figure gives the same bytes (diffable, reproducible)
    with _dense_rasterized(fig), _no_layout_engine(fig), _frozen_ticks(fig), \
            matplotlib.rc_context({"svg.hashsalt": "jointlock"}):  # fmt: skip
        fig.savefig(buf, format="svg", dpi=dpi, metadata={"Date": None}, bbox_inches=bbox)
    return buf.getvalue()


def render_files(fig: Any, dpi: float, *, tight: bool = True) -> tuple[bytes, bytes]:
    """The figure as PNG (:func:`render_png`) and SVG (:func:`render_svg`) of the same extent,
    the ticks computed once for both."""
    with _frozen_ticks(fig):
        png, bbox = render_png(fig, dpi, tight=tight)
        return png, render_svg(fig, dpi, bbox)
