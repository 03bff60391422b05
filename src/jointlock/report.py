"""Writing results for people: atomic file writes, arm drawings and a self-contained HTML page.

Library code here never prints.  Images are embedded as base64 PNG so a report is a single
file that opens without a network.
"""

from __future__ import annotations

import base64
import html
import io
import json
import os
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .kinematics import chain_state, com_positions
from .model import ArmModel


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` via a temporary file and a rename, so an interrupted run
    never leaves a half-written file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | Path, obj: Any) -> None:
    from .cli._common import _plain

    atomic_write_text(path, json.dumps(_plain(obj), indent=2, allow_nan=False) + "\n")


def arm_points(model: ArmModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Polyline through the root, every joint origin and the end effector (k, 3) [m], and
    the link centres of mass (n, 3) [m], for one configuration (root frame)."""
    state = chain_state(model, q)
    pts = np.vstack([np.zeros(3), state.positions, state.ee_position])
    return pts, com_positions(model, q, state)


def draw_arm(ax: Any, model: ArmModel, q: np.ndarray, *, label: str = "", color: str | None = None) -> None:
    """Draw the arm at ``q`` (n,) [rad] on a matplotlib 3-D axis."""
    pts, coms = arm_points(model, q)
    (line,) = ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], "-o", lw=2.5, ms=4, label=label, color=color)
    ax.scatter(coms[:, 0], coms[:, 1], coms[:, 2], marker="x", s=20, color=line.get_color())
    ax.scatter(*pts[-1], marker="*", s=80, color=line.get_color())


def set_equal_3d(ax: Any, points: np.ndarray) -> None:
    """Equal scaling on a 3-D axis around ``points`` (k, 3)."""
    centre = (points.max(axis=0) + points.min(axis=0)) / 2
    radius = max(float(np.ptp(points, axis=0).max()) / 2, 1e-3)
    ax.set_xlim(centre[0] - radius, centre[0] + radius)
    ax.set_ylim(centre[1] - radius, centre[1] + radius)
    ax.set_zlim(centre[2] - radius, centre[2] + radius)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")


def figure_png(fig: Any, dpi: int = 110) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    return buf.getvalue()


@dataclass
class Section:
    """One part of an HTML report: a heading, paragraphs, tables and images (PNG bytes)."""

    title: str
    paragraphs: list[str] = field(default_factory=list)
    tables: list[tuple[Sequence[str], Iterable[Sequence[Any]]]] = field(default_factory=list)
    images: list[tuple[str, bytes]] = field(default_factory=list)


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#1b1f23;line-height:1.45}
h1{border-bottom:2px solid #345;padding-bottom:.3em}h2{margin-top:2em;color:#234}
table{border-collapse:collapse;margin:1em 0;font-size:.92em}
td,th{border:1px solid #ccd;padding:.3em .6em;text-align:right}th{background:#eef2f6}
td:first-child,th:first-child{text-align:left}
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #dde}
figcaption{font-size:.9em;color:#555}.ok{color:#176f2c}.bad{color:#b00020;font-weight:600}
"""


def _cell(value: Any) -> str:
    if isinstance(value, float) or isinstance(value, np.floating):
        return f"{float(value):.6g}"
    return html.escape(str(value))


def render_html(title: str, sections: Sequence[Section], intro: str = "") -> str:
    """A self-contained HTML page (inline CSS, images as data URIs, no scripts)."""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    if intro:
        parts.append(f"<p>{intro}</p>")
    for sec in sections:
        parts.append(f"<h2>{html.escape(sec.title)}</h2>")
        parts.extend(f"<p>{p}</p>" for p in sec.paragraphs)
        for header, rows in sec.tables:
            parts.append("<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>")
            parts.extend("<tr>" + "".join(f"<td>{_cell(v)}</td>" for v in row) + "</tr>" for row in rows)
            parts.append("</table>")
        for caption, png in sec.images:
            uri = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
            parts.append(
                f'<figure><img src="{uri}" alt="{html.escape(caption)}">'
                f"<figcaption>{html.escape(caption)}</figcaption></figure>"
            )
    parts.append("</body></html>")
    return "\n".join(parts)
