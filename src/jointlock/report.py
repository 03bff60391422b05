"""A self-contained HTML page of results (sections, facts, tables, figures).

Library code here never prints.  Images are embedded as base64 PNG so a report is a single
file that opens without a network: inline CSS, no external resources; the only script is the
interactive 3-D view's (plotly.js, vendored, inline, once per page, only when a section has
one).  A test renders every example's report in headless Chromium, checks the console stays
clean, the 3-D view is drawn and its animation advances.

A report is a list of :class:`Section` objects rendered by :func:`render_html`: headings,
paragraphs, key/value facts, tables (with kept/broken cells coloured), preformatted blocks
(command lines), notes (assumptions and readings) and figures.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .io.files import (  # noqa: F401  (re-exported: the writers used to live here)
    atomic_write_bytes,
    atomic_write_json,
    atomic_write_text,
    figure_png,
    figure_svg,
    save_figure,
)
from .jobs._common import AT_LIMIT
from .plots.animation import animation_html, plotly_js
from .plots.arm import arm_figure, arm_points, draw_arm, set_equal_3d  # noqa: F401  (re-exported)


def limit_status(value: float, limit: float) -> str:
    """``"kept"`` when ``value`` stays at least :data:`AT_LIMIT` of ``limit`` below it, ``"at the
    limit"`` when it reaches it within that share (up to a relative 1e-9), else ``"BROKEN"``."""
    if value > limit * (1 + 1e-9):
        return "BROKEN"
    return "kept" if value <= limit * (1 - AT_LIMIT) else "at the limit"


def limits_rows(
    joints: Sequence[int], values: Sequence[float], limits: Sequence[float], quantity: str, unit: str
) -> list[list[Any]]:
    """Rows ``[joint, quantity, peak, limit, margin [% of the limit], status]`` for a limits
    table (the margin ``100 (1 - peak / limit)``, one decimal, as the command prints it); status
    is ``"kept"``, ``"at the limit"`` or ``"BROKEN"`` (coloured by :func:`render_html`)."""
    rows = []
    for j, v, lim in zip(joints, values, limits):
        v, lim = abs(float(v)), float(lim)
        margin = round(100.0 * (1.0 - v / lim), 1) + 0.0 if lim > 0 else ""  # + 0.0: no "-0.0"
        rows.append([j, f"{quantity} [{unit}]", v, lim, margin, limit_status(v, lim)])
    return rows


#: Header of :func:`limits_rows` tables.
LIMITS_HEADER = ["joint", "quantity", "peak |value|", "limit", "margin [% of the limit]", "status"]


@dataclass
class Section:
    """One part of an HTML report: a heading, paragraphs (HTML allowed), key/value facts,
    tables, preformatted blocks, notes (assumptions, readings) and images (PNG bytes).

    A table is ``(header, rows)`` or ``(header, rows, caption)``; a cell reading ``"kept"``,
    ``"BROKEN"``, ``"reproduced"`` or ``"not reproduced"`` is coloured.  ``animations`` are
    ``(caption, plotly figure)`` pairs (:func:`jointlock.plots.animation.animation_figure`).
    """

    title: str
    paragraphs: list[str] = field(default_factory=list)
    tables: list[tuple[Any, ...]] = field(default_factory=list)
    images: list[tuple[str, bytes]] = field(default_factory=list)
    facts: list[tuple[str, Any]] = field(default_factory=list)
    code: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    level: int = 2
    animations: list[tuple[str, dict[str, Any]]] = field(default_factory=list)


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#1b1f23;line-height:1.45}
h1{border-bottom:2px solid #345;padding-bottom:.3em}h2{margin-top:2em;color:#234}
table{border-collapse:collapse;margin:1em 0;font-size:.92em}
td,th{border:1px solid #ccd;padding:.3em .6em;text-align:right}th{background:#eef2f6}
td:first-child,th:first-child{text-align:left}
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #dde}
figcaption{font-size:.9em;color:#555}.ok{color:#176f2c}.bad{color:#b00020;font-weight:600}
.warn{color:#8a5a00}dl.facts{display:grid;grid-template-columns:max-content auto;gap:.2em 1em}
dl.facts dt{font-weight:600}dl.facts dd{margin:0}pre{background:#f6f8fa;padding:.6em;overflow-x:auto;
font-size:.85em;white-space:pre-wrap}nav ul{columns:2}.notes{background:#fffbe6;border-left:4px solid #e0c050;
padding:.4em 1em}caption{caption-side:top;text-align:left;font-weight:600;padding:.2em 0}
@media print{nav{display:none}}
"""


_STATUS_CLASS = {
    "kept": "ok",
    "reproduced": "ok",
    "feasible": "ok",
    "yes": "ok",
    "BROKEN": "bad",
    "not reproduced": "bad",
    "INFEASIBLE": "bad",
    "ours only": "warn",
    "at the limit": "warn",
}


def _cell(value: Any) -> str:
    if value is None:
        return "&mdash;"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, float) or isinstance(value, np.floating):
        v = float(value)
        return f"{v:.6g}" if np.isfinite(v) else "&mdash;"
    if isinstance(value, (list, tuple, np.ndarray)):
        return html.escape(", ".join(_cell(v) for v in value))
    text = str(value)
    cls = _STATUS_CLASS.get(text) or next(
        (c for k, c in _STATUS_CLASS.items() if text.startswith(k + " ") or text.startswith(k + ":")), None
    )
    return f'<span class="{cls}">{html.escape(text)}</span>' if cls else html.escape(text)


def _anchor(i: int) -> str:
    return f"s{i}"


def render_html(
    title: str,
    sections: Sequence[Section],
    intro: str = "",
    *,
    toc: bool = False,
    footer: str = "",
) -> str:
    """A self-contained HTML page (inline CSS, images as data URIs, plotly.js inline when a
    section has an animation).

    ``intro`` and paragraphs may hold HTML; everything else is escaped.  ``toc`` adds a list
    of the sections at the top.
    """
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style>",
        f"<script>{plotly_js()}</script>" if any(sec.animations for sec in sections) else "",
        "</head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    if intro:
        parts.append(f"<p>{intro}</p>")
    if toc and sections:
        parts.append("<nav><ul>")
        parts.extend(
            f'<li><a href="#{_anchor(i)}">{html.escape(sec.title)}</a></li>'
            for i, sec in enumerate(sections)
            if sec.level == 2
        )
        parts.append("</ul></nav>")
    for i, sec in enumerate(sections):
        tag = f"h{min(max(sec.level, 2), 4)}"
        parts.append(f'<{tag} id="{_anchor(i)}">{html.escape(sec.title)}</{tag}>')
        parts.extend(f"<p>{p}</p>" for p in sec.paragraphs)
        if sec.facts:
            parts.append('<dl class="facts">')
            parts.extend(f"<dt>{html.escape(str(k))}</dt><dd>{_cell(v)}</dd>" for k, v in sec.facts)
            parts.append("</dl>")
        for table in sec.tables:
            header, rows = table[0], table[1]
            caption = f"<caption>{html.escape(table[2])}</caption>" if len(table) > 2 and table[2] else ""
            parts.append(
                f"<table>{caption}<tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in header) + "</tr>"
            )
            parts.extend("<tr>" + "".join(f"<td>{_cell(v)}</td>" for v in row) + "</tr>" for row in rows)
            parts.append("</table>")
        parts.extend(f"<pre>{html.escape(block)}</pre>" for block in sec.code)
        if sec.notes:
            parts.append('<div class="notes"><ul>')
            parts.extend(f"<li>{html.escape(n)}</li>" for n in sec.notes)
            parts.append("</ul></div>")
        for caption, figure in sec.animations:
            parts.append(
                f"<figure>{animation_html(figure)}<figcaption>{html.escape(caption)}</figcaption></figure>"
            )
        for caption, png in sec.images:
            uri = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
            parts.append(
                f'<figure><img src="{uri}" alt="{html.escape(caption)}">'
                f"<figcaption>{html.escape(caption)}</figcaption></figure>"
            )
    if footer:
        parts.append(f"<footer><p>{footer}</p></footer>")
    parts.append("</body></html>")
    return "\n".join(parts)
