"""Figures of a Monte Carlo workspace (002 Figs. 2-3): projections and 3-D point clouds."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ._common import new_axes, new_figure

#: Axes (indices into x, y, z) of each projection plane.
PLANES: dict[Literal["xy", "xz", "yz"], tuple[int, int]] = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
#: Colours of the full arm's and the locked arm's points.
FULL_COLOUR, LOCKED_COLOUR = "tab:blue", "tab:red"


def plot_workspace_projection(
    full: ArrayLike,
    locked: ArrayLike | None = None,
    *,
    plane: Literal["xy", "xz", "yz"] = "xy",
    max_points: int = 20000,
    legend: bool = True,
    ax: Any | None = None,
) -> Any:
    """The end-effector positions of the full arm (and of the locked arm) projected on one
    plane, equal axes [m].

    Parameters
    ----------
    full, locked
        (N, 3) and (M, 3) positions [m], root frame (``locked`` may be None); the first
        ``max_points`` of each are drawn.
    plane
        ``"xy"``, ``"xz"`` or ``"yz"``.
    legend
        Draw the legend ("full arm", "locked arm").
    ax
        Axis to draw on; None: a new 5 x 4.5 inch figure.

    Returns
    -------
    The axis.
    """
    i, j = PLANES[plane]
    ax = new_axes(ax, (5, 4.5))
    f_pts = np.asarray(full, dtype=float)[:max_points]
    ax.scatter(f_pts[:, i], f_pts[:, j], s=0.3, alpha=0.3, label="full arm", color=FULL_COLOUR)
    if locked is not None:
        l_pts = np.asarray(locked, dtype=float)[:max_points]
        ax.scatter(l_pts[:, i], l_pts[:, j], s=0.3, alpha=0.3, label="locked arm", color=LOCKED_COLOUR)
    ax.set_xlabel(f"{plane[0]} [m]")
    ax.set_ylabel(f"{plane[1]} [m]")
    ax.set_aspect("equal")
    ax.set_title(f"{plane} projection")
    if legend:
        ax.legend(markerscale=20)
    return ax


def plot_workspace_projections(
    full: ArrayLike, locked: ArrayLike | None = None, *, max_points: int = 20000, fig: Any | None = None
) -> Any:
    """The xy, xz and yz projections side by side (:func:`plot_workspace_projection`; legend
    on the first).  ``fig=None``: a new 14 x 4.5 inch figure.  Returns the figure."""
    fig = new_figure(fig, (14, 4.5))
    axes = fig.subplots(1, 3)
    for k, (ax, plane) in enumerate(zip(axes, PLANES)):
        plot_workspace_projection(full, locked, plane=plane, max_points=max_points, legend=k == 0, ax=ax)
    fig.tight_layout()
    return fig


def plot_workspace_cloud(
    points: ArrayLike,
    *,
    title: str = "",
    color: str = FULL_COLOUR,
    max_points: int = 5000,
    ax: Any | None = None,
) -> Any:
    """The first ``max_points`` of ``points`` (N, 3) [m] as a 3-D point cloud (002 Figs. 2-3).
    ``ax=None``: a 3-D axis on a new 5.5 x 5 inch figure.  Returns the axis."""
    ax = new_axes(ax, (5.5, 5), projection="3d")
    pts = np.asarray(points, dtype=float)[:max_points]
    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], s=0.5, alpha=0.4, color=color)
    ax.set_title(title)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    return ax


def plot_workspace_clouds(
    full: ArrayLike, locked: ArrayLike | None = None, *, max_points: int = 5000, fig: Any | None = None
) -> Any:
    """The full arm's cloud (002 Fig. 2) and, beside it, the locked arm's (Fig. 3), each on
    its own 3-D axis, both on the same axis limits (the cube around both clouds, equal in x, y
    and z) so that the two compare by eye.  ``fig=None``: a new 11 x 5 inch figure.  Returns the figure."""
    fig = new_figure(fig, (11, 5))
    clouds = [("full arm", full, FULL_COLOUR)] + (
        [("locked arm", locked, LOCKED_COLOUR)] if locked is not None else []
    )
    every = np.vstack([np.asarray(p, dtype=float)[:max_points] for _, p, _ in clouds])
    centre = (every.max(axis=0) + every.min(axis=0)) / 2
    half = max(float(np.ptp(every, axis=0).max()) / 2, 1e-3)
    for k, (title, pts, color) in enumerate(clouds):
        ax = fig.add_subplot(1, len(clouds), k + 1, projection="3d")
        plot_workspace_cloud(pts, title=title, color=color, max_points=max_points, ax=ax)
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            setter(c - half, c + half)
        ax.set_box_aspect((1, 1, 1))
    fig.tight_layout()
    return fig
