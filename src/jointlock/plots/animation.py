"""Interactive, animated 3-D view of the arm (plotly.js, offline, in one HTML file).

:func:`animation_figure` turns one or more :class:`~jointlock.plots.motion.ArmMotion` into a
plotly figure (plain ``data`` / ``layout`` / ``frames`` dictionaries, no Python plotly
needed): per motion the arm's links through every joint origin to the end effector, each
joint's axis, the link centres of mass, the end effector's path so far and, from the instant
it locks, the locked joint marked in red; the joint numbers on the first motion; the target
path when there is one; the spacecraft as a translucent box moving with its attitude and drift
when the base is free.  Play / Pause buttons and a time slider step through the frames, the
title says which joint is locked at each instant; the mouse orbits and zooms.

:func:`animation_html` gives the ``<div>`` and ``<script>`` of one view; the page needs
plotly.js once (:func:`plotly_js`, the gl3d bundle vendored from npm by
``scripts/vendor_plotly.sh``, MIT licence beside it): :func:`standalone_html` and the run
report include it inline, so the file opens with no network.  A page's address ending in
``#jl-play`` plays every view at once, ``#jl-frame=K`` shows frame K (used by the browser test,
handy for a link to a moment); each view's ``data-frame`` attribute names the frame shown.
"""

from __future__ import annotations

import dataclasses
import hashlib
import html
import json
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..collision import clearance, collision_pairs
from ..errors import ConfigurationError
from ..model import ArmModel
from .motion import ArmMotion, _nearest, drawn_arm, frame_times, motion_points, spacecraft_box

#: Colours of successive motions (plotly's first three).
MOTION_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")
LOCKED_COLOUR = "#e31a1c"
#: The 12 edges of spacecraft_box's corners (corner index = 4 i_x + 2 i_y + i_z).
_BOX_EDGES = tuple((a, a | bit) for a in range(8) for bit in (1, 2, 4) if not a & bit)


def _xyz(points: np.ndarray) -> dict[str, list[float | None]]:
    """``x``, ``y``, ``z`` lists of (k, 3) points, NaN rows as gaps (null)."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    out: dict[str, list[float | None]] = {}
    for i, name in enumerate("xyz"):
        out[name] = [None if not np.isfinite(v) else round(float(v), 5) for v in p[:, i]]
    return out


def _segments(starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(3k, 3) points of k separate segments (NaN rows between them)."""
    gap = np.full_like(starts, np.nan)
    return np.stack([starts, ends, gap], axis=1).reshape(-1, 3)


def _frame_traces(
    points: dict[str, np.ndarray], f: int, motion: ArmMotion, model: ArmModel, t: float, scale: float, first: bool, ee_trail: np.ndarray
) -> list[dict[str, Any]]:
    """The moving traces of one motion at frame ``f`` (same order as :func:`_static_traces`)."""
    joints, ee, base = points["joints"][f], points["ee"][f], points["base"][f]
    chain = np.vstack([base, joints, ee])
    locked_now = [j for j, s in motion.locks if s <= t + 1e-12]
    numbers = list(model.joint_numbers)
    locked_pts = np.array([joints[numbers.index(j)] for j in locked_now]).reshape(-1, 3)
    traces: list[dict[str, Any]] = [
        _xyz(chain),
        _xyz(_segments(joints - scale * points["axes"][f], joints + scale * points["axes"][f])),
        _xyz(points["coms"][f]),
        _xyz(ee_trail),
        {**_xyz(locked_pts), "text": [f"joint {j} locked" for j in locked_now]},
    ]
    if first:
        traces.append({**_xyz(joints), "text": _joint_labels(joints, numbers, scale)})
    return traces


def _trace_styles(motion: ArmMotion, colour: str, first: bool, width: int) -> list[dict[str, Any]]:
    group = motion.label
    common = {"type": "scatter3d", "legendgroup": group, "hoverinfo": "skip"}
    styles: list[dict[str, Any]] = [
        {**common, "mode": "lines+markers", "name": motion.label, "hoverinfo": "name",
         "line": {"color": colour, "width": width}, "marker": {"size": 4, "color": colour}},
        {**common, "mode": "lines", "name": "joint axes", "showlegend": False,
         "line": {"color": colour, "width": 2, "dash": "dot"}},
        {**common, "mode": "markers", "name": "link centres of mass", "showlegend": False,
         "marker": {"size": 3, "color": colour, "symbol": "x"}},
        {**common, "mode": "lines", "name": f"{motion.label}: end-effector path", "showlegend": False,
         "line": {"color": colour, "width": 2}},
        {**common, "mode": "markers", "name": "locked joint", "showlegend": first, "hoverinfo": "text",
         "marker": {"size": 9, "color": LOCKED_COLOUR, "symbol": "diamond", "line": {"color": "black", "width": 1}}},
    ]  # fmt: skip
    if first:
        styles.append({**common, "mode": "text", "name": "joint numbers", "showlegend": False,
                       "textfont": {"size": 13, "color": "black"}, "textposition": "top center"})  # fmt: skip
    return styles


def animation_figure(
    model: ArmModel, motions: ArmMotion | list[ArmMotion], *, title: str = "", max_frames: int = 120
) -> dict[str, Any]:
    """A plotly figure (``data``, ``layout``, ``frames``, ``config``) animating ``motions``.

    Parameters
    ----------
    model
        The arm; a locked model is drawn as its full arm (``model.unlocked``), the locked joint
        at its angle and marked.
    motions
        One motion or several on the same clock (e.g. the jump study's runs without and with
        compensation), drawn in :data:`MOTION_COLOURS`.  ``q`` has one angle per joint of the
        full arm, or, for a locked model, one per movable joint (the locked angles are then
        inserted and the locked joints marked throughout).
    title
        Figure title; each frame adds the time and the joints locked by then.
    max_frames
        At most this many evenly spaced frames (plus each lock's instant).
    """
    arm = drawn_arm(model)
    motions = [motions] if isinstance(motions, ArmMotion) else list(motions)
    if not motions or not all(isinstance(m, ArmMotion) for m in motions):
        raise ConfigurationError(
            f"animation_figure needs one or more ArmMotion; got {[type(m).__name__ for m in motions] or 'none'}"
        )
    motions = [_on_full_arm(model, arm, m) for m in motions]
    times = frame_times(motions, max_frames)
    points = [motion_points(arm, m, times) for m in motions]
    extent = np.vstack([np.vstack([p["joints"].reshape(-1, 3), p["ee"], p["base"]]) for p in points])
    extent = np.vstack([extent, *[m.target for m in motions if m.target is not None]])
    box = spacecraft_box(arm)
    boxes = [None if box is None else p["base"][:, None, :] + np.einsum("fij,kj->fki", p["base_rotation"], box) for p in points]
    overlaps = [_overlaps(arm, m, p, times) for m, p in zip(motions, points)]
    if box is not None:
        extent = np.vstack([extent, *[b.reshape(-1, 3) for b in boxes if b is not None]])
    centre = (extent.max(axis=0) + extent.min(axis=0)) / 2
    radius = max(float(np.ptp(extent, axis=0).max()) / 2 * 1.05, 1e-3)
    scale = radius / 8  # joint-axis half length

    data: list[dict[str, Any]] = []
    moving: list[int] = []  # indices of the traces the frames update
    for i, (m, p) in enumerate(zip(motions, points)):
        colour = MOTION_COLOURS[i % len(MOTION_COLOURS)]
        styles = _trace_styles(m, colour, i == 0, max(9 - 3 * i, 4))  # later arms thinner: both stay visible
        first = _frame_traces(p, 0, m, arm, float(times[0]), scale, i == 0, p["ee"][:1])
        moving += list(range(len(data), len(data) + len(styles)))
        data += [{**style, **tr} for style, tr in zip(styles, first)]
        if m.target is not None and i == next(k for k, mm in enumerate(motions) if mm.target is not None):
            data.append({"type": "scatter3d", "mode": "lines", "name": m.target_label, "hoverinfo": "name",
                         "line": {"color": "black", "width": 3, "dash": "dash"}, **_xyz(m.target)})  # fmt: skip
        box_i = boxes[i]
        if box_i is not None:
            moving.append(len(data))
            name = "spacecraft" if m.moving_base else "spacecraft (held)" if arm.floating else "base body (fixed)"
            data.append(_box_trace(box_i[0], colour, name if len(motions) == 1 else f"{name}, {m.label}"))
        over = overlaps[i]
        if over is not None:
            moving.append(len(data))
            label = "overlap (deepest pair)" if len(motions) == 1 else f"overlap, {m.label}"
            data.append({"type": "scatter3d", "mode": "lines+markers", "name": label, "hoverinfo": "text",
                         "line": {"color": "red", "width": 10}, "marker": {"color": "red", "size": 5},
                         **_overlap_trace(*over[0])})  # fmt: skip

    frames = []
    for f, t in enumerate(times):
        traces: list[dict[str, Any]] = []
        for i, (m, p) in enumerate(zip(motions, points)):
            traces += _frame_traces(p, f, m, arm, float(t), scale, i == 0, p["ee"][: f + 1])
            box_i = boxes[i]
            if box_i is not None:
                traces.append(_xyz(_box_lines(box_i[f])))
            over = overlaps[i]
            if over is not None:
                traces.append(_overlap_trace(*over[f]))
        frames.append({"name": str(f), "data": traces, "traces": moving, "layout": {"title": {"text": _frame_title(title, motions, float(t))}}})

    ranges = [[float(c - radius), float(c + radius)] for c in centre]
    duration_ms = int(np.clip(1000 * (times[-1] - times[0]) / max(times.size - 1, 1), 30, 200))
    layout = {
        "title": {"text": _frame_title(title, motions, float(times[0])), "font": {"size": 14}},
        "scene": {
            "aspectmode": "cube",
            **{f"{a}axis": {"range": r, "title": {"text": f"{a} [m]"}} for a, r in zip("xyz", ranges)},
            "camera": {"eye": {"x": 1.5, "y": 1.5, "z": 1.0}},
        },
        "legend": {"x": 0.0, "y": 1.0, "bgcolor": "rgba(255,255,255,0.7)"},
        "margin": {"l": 0, "r": 0, "t": 40, "b": 0},
        "updatemenus": [{
            "type": "buttons", "direction": "left", "showactive": False,
            "x": 0.0, "y": 0.0, "xanchor": "left", "yanchor": "top", "pad": {"t": 10},
            "buttons": [
                {"label": "Play", "method": "animate",
                 "args": [None, {"frame": {"duration": duration_ms, "redraw": True}, "fromcurrent": True,
                                 "transition": {"duration": 0}}]},
                {"label": "Pause", "method": "animate",
                 "args": [[None], {"mode": "immediate", "frame": {"duration": 0, "redraw": False},
                                   "transition": {"duration": 0}}]},
            ],
        }],
        "sliders": [{
            "active": 0, "x": 0.15, "len": 0.85, "y": 0.0, "yanchor": "top", "pad": {"t": 10},
            "currentvalue": {"prefix": "t = ", "suffix": " s", "font": {"color": "#1b1f23"}},
            "font": {"color": "rgba(0,0,0,0)"},  # one tick label per frame would overlap: the time is above
            "steps": [
                {"label": f"{t:.3g}", "method": "animate",
                 "args": [[str(f)], {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
                                     "transition": {"duration": 0}}]}
                for f, t in enumerate(times)
            ],
        }],
    }  # fmt: skip
    config = {"displaylogo": False, "responsive": True, "showLink": False, "showSendToCloud": False}
    return {"data": data, "layout": layout, "frames": frames, "config": config}


def _on_full_arm(model: ArmModel, arm: ArmModel, motion: ArmMotion) -> ArmMotion:
    """``motion`` on the drawn (full) arm: a locked model's healthy-joint angles expanded with
    its lock angles, its locked joints locked from the start."""
    if arm is model or motion.q.shape[1] != model.dof:
        return motion
    locks = (*motion.locks, *((lj.number, float(motion.t[0])) for lj in model.locked if lj.number not in dict(motion.locks)))
    return dataclasses.replace(motion, q=model.expand(motion.q), locks=locks)


def _overlaps(arm: ArmModel, motion: ArmMotion, points: dict[str, Any], times: np.ndarray) -> list[tuple[np.ndarray, str]] | None:
    """Per frame, the witness points (2, 3) of the deepest overlap of the arm with its bus or
    itself, in the motion's first frame, and a hover text; (0, 3) when it overlaps nothing.
    None for an arm without collision shapes, or whose meshes could not be read (its clearance is
    refused where it is asked for)."""
    if arm.unread_meshes or not collision_pairs(arm).names:
        return None
    result = clearance(arm, motion.q[_nearest(motion.t, times)])
    world = points["base"][:, None, :] + np.einsum("fij,fkj->fki", points["base_rotation"], result.witness)
    return [
        (world[f], f"{result.pair_at((f,))}: {-float(result.distance[f]):.3f} m overlap")
        if result.distance[f] < 0
        else (np.zeros((0, 3)), "")
        for f in range(times.size)
    ]


def _overlap_trace(witness: np.ndarray, text: str) -> dict[str, Any]:
    return {**_xyz(witness), "hovertext": [text] * len(witness)}


def _box_lines(corners: np.ndarray) -> np.ndarray:
    a, b = zip(*_BOX_EDGES)
    return _segments(corners[list(a)], corners[list(b)])


def _box_trace(corners: np.ndarray, colour: str, name: str) -> dict[str, Any]:
    # edges only: the arm is often mounted on (or drawn inside) the spacecraft's box
    return {"type": "scatter3d", "mode": "lines", "name": name, "hoverinfo": "name",
            "line": {"color": colour, "width": 3}, **_xyz(_box_lines(corners))}  # fmt: skip


def _joint_labels(joints: np.ndarray, numbers: list[int], scale: float) -> list[str]:
    """Joint numbers, joints at one point labelled together ("1,2") on the first of them."""
    labels = [str(n) for n in numbers]
    for a in range(len(numbers)):
        if not labels[a]:
            continue
        # joints closer than a quarter of an axis' half length would print their numbers over each other
        same = [b for b in range(a + 1, len(numbers)) if np.linalg.norm(joints[b] - joints[a]) < 0.25 * scale]
        for b in same:
            labels[a] += f",{labels[b]}" if labels[b] else ""
            labels[b] = ""
    return labels


def _frame_title(title: str, motions: list[ArmMotion], t: float) -> str:
    locks = sorted({(j, s) for m in motions for j, s in m.locks}, key=lambda js: js[1])
    done = [f"joint {j}" for j, s in locks if s <= t + 1e-12]
    coming = [f"joint {j} at {s:.3g} s" for j, s in locks if s > t + 1e-12]
    state = (", ".join(done) + " locked") if done else "all joints healthy"
    if coming:
        state += "; locks " + ", ".join(coming)
    head = f"{html.escape(title)} · " if title else ""
    return f"{head}t = {t:.3g} s · {state}"


@cache
def plotly_js() -> str:
    """The vendored plotly.js gl3d bundle (``jointlock/data/plotly-gl3d.min.js``, MIT)."""
    return resources.files("jointlock").joinpath("data/plotly-gl3d.min.js").read_text(encoding="utf-8")


def _json(obj: Any) -> str:
    # inside <script> no "<" at all: "</script" would end the element, "<!--" open a comment
    return json.dumps(obj, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")


_SCRIPT = """<script>(function(){var fig=%s;var gd=document.getElementById(%s);
Plotly.newPlot(gd,fig.data,fig.layout,fig.config).then(function(){return Plotly.addFrames(gd,fig.frames);}).then(function(){
gd.setAttribute('data-frame','0');gd.on('plotly_animatingframe',function(e){gd.setAttribute('data-frame',e.name);});
var h=location.hash,m=/^#jl-frame=(\\d+)$/.exec(h);
if(h==='#jl-play'){Plotly.animate(gd,null,{frame:{duration:20,redraw:true},transition:{duration:0}});}
else if(m){Plotly.animate(gd,[String(Math.min(+m[1],fig.frames.length-1))],{mode:'immediate',frame:{duration:0,redraw:true},transition:{duration:0}});}
});})();</script>"""


def animation_html(figure: dict[str, Any], *, height_px: int = 560) -> str:
    """The ``<div>`` and ``<script>`` showing ``figure`` (:func:`animation_figure`); the page
    must load :func:`plotly_js` first."""
    text = _json(figure)
    div_id = "jl-animation-" + hashlib.sha1(text.encode()).hexdigest()[:12]  # the same figure, the same page
    return (
        f'<div class="jl-animation" id="{div_id}" data-frames="{len(figure["frames"])}" '
        f'style="width:100%;height:{int(height_px)}px"></div>\n' + _SCRIPT % (text, _json(div_id))
    )


def standalone_html(figure: dict[str, Any], title: str = "jointlock: the arm in motion") -> str:
    """A page of its own (plotly.js inline: opens from a file, no network)."""
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{html.escape(title)}</title><script>{plotly_js()}</script></head>"
        f"<body style=\"margin:0;font-family:sans-serif\">\n{animation_html(figure, height_px=640)}\n</body></html>\n"
    )


def write_animation_html(
    path: str | Path, model: ArmModel, motions: ArmMotion | list[ArmMotion], *, title: str = ""
) -> Path:
    """Write :func:`standalone_html` of :func:`animation_figure` to ``path``; returns it."""
    from ..io.files import atomic_write_text

    path = Path(path)
    atomic_write_text(path, standalone_html(animation_figure(model, motions, title=title), title or "jointlock"))
    return path
