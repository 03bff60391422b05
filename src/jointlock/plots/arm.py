"""3-D drawing of an arm at one or more configurations."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..kinematics import chain_state, com_positions
from ..model import ArmModel
from ._common import new_axes, new_figure


def arm_points(model: ArmModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Polyline through the root, every joint origin and the end effector (k, 3) [m], and
    the link centres of mass (n, 3) [m], for one configuration ``q`` (n,) [rad] (root frame)."""
    state = chain_state(model, q)
    pts = np.vstack([np.zeros(3), state.positions, state.ee_position])
    return pts, com_positions(model, q, state)


def draw_arm(ax: Any, model: ArmModel, q: np.ndarray, *, label: str = "", color: str | None = None) -> Any:
    """Draw the arm at ``q`` (n,) [rad] on the 3-D axis ``ax`` (joint origins as dots, link
    centres of mass as crosses, the end effector as a star); returns ``ax``."""
    pts, coms = arm_points(model, q)
    (line,) = ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], "-o", lw=2.5, ms=4, label=label, color=color)
    ax.scatter(coms[:, 0], coms[:, 1], coms[:, 2], marker="x", s=20, color=line.get_color())
    ax.scatter(*pts[-1], marker="*", s=80, color=line.get_color())
    return ax


def set_equal_3d(ax: Any, points: np.ndarray) -> None:
    """Equal scaling on a 3-D axis around ``points`` (k, 3) [m]."""
    centre = (points.max(axis=0) + points.min(axis=0)) / 2
    radius = max(float(np.ptp(points, axis=0).max()) / 2, 1e-3)
    ax.set_xlim(centre[0] - radius, centre[0] + radius)
    ax.set_ylim(centre[1] - radius, centre[1] + radius)
    ax.set_zlim(centre[2] - radius, centre[2] + radius)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")


#: Colours of successive configurations.
ARM_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:orange", "0.5")


def plot_arm(
    model: ArmModel, configurations: dict[str, np.ndarray], *, title: str = "", ax: Any | None = None
) -> Any:
    """Draw ``model`` at each ``{label: q (n,) [rad]}`` on one 3-D axis (root frame, equal
    axes), e.g. the configuration at failure and the halt configuration.  Returns the axis."""
    ax = new_axes(ax, (6.0, 5.0), projection="3d")
    pts = []
    for i, (label, q) in enumerate(configurations.items()):
        q = np.asarray(q, dtype=float)
        draw_arm(ax, model, q, label=label, color=ARM_COLOURS[i % len(ARM_COLOURS)])
        pts.append(arm_points(model, q)[0])
    set_equal_3d(ax, np.vstack(pts))
    ax.legend(loc="upper left", fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def arm_figure(
    model: ArmModel, configurations: dict[str, np.ndarray], *, title: str = "", fig: Any | None = None
) -> Any:
    """:func:`plot_arm` on a figure of its own (``fig``, else a new pyplot one); returns it."""
    fig = new_figure(fig, (6.0, 5.0))
    plot_arm(model, configurations, title=title, ax=fig.add_subplot(projection="3d"))
    return fig
