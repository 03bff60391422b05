"""Figures of a straight-line re-plan (002 Figs. 11-14 and 17-20), all against time."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..ik import zyx_angles
from ..planning.replan import ReplanResult
from ._common import new_axes, new_figure


def _finish(ax: Any) -> None:
    """What every panel has: time on x, a legend, a light grid."""
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)


def plot_replan_joints(plan: ReplanResult, *, ax: Any | None = None) -> Any:
    """Every joint's angle [deg] against time [s] (002 Figs. 11 and 17), the locked one
    included.  ``ax=None``: a new 7 x 4 inch figure.  Returns the axis."""
    ax = new_axes(ax, (7, 4))
    for k in range(plan.q_full.shape[1]):
        ax.plot(plan.times, np.degrees(plan.q_full[:, k]), label=f"joint {k + 1}")
    ax.set_ylabel("angle [deg]")
    _finish(ax)
    return ax


def plot_replan_pose(plan: ReplanResult, *, fig: Any | None = None) -> Any:
    """Two panels (002 Figs. 12 and 18): the end-effector position [mm] against the line's,
    and its ZYX Euler angles [deg], against time [s].  ``fig=None``: a new 11 x 4 inch figure.
    Returns the figure."""
    fig = new_figure(fig, (11, 4))
    a1, a2 = fig.subplots(1, 2)
    t = plan.times
    for k, lab in enumerate("xyz"):
        a1.plot(t, plan.actual[:, k, 3] * 1e3, label=f"{lab} actual")
        a1.plot(t, plan.nominal[:, k, 3] * 1e3, "--", lw=1, label=f"{lab} line")
    eul = np.degrees(zyx_angles(plan.actual[:, :3, :3]))
    for k, lab in enumerate(("yaw", "pitch", "roll")):
        a2.plot(t, eul[:, k], label=lab)
    a1.set_ylabel("position [mm]")
    a2.set_ylabel("ZYX Euler [deg]")
    _finish(a1)
    _finish(a2)
    fig.tight_layout()
    return fig


def plot_replan_errors(plan: ReplanResult, *, fig: Any | None = None) -> Any:
    """Two panels (002 Figs. 13 and 19): the position error [mm] against the target (the line
    rotated by gamma) and against the line, and the rotation errors and gamma [deg], against
    time [s].  ``fig=None``: a new 11 x 4 inch figure.  Returns the figure."""
    fig = new_figure(fig, (11, 4))
    a1, a2 = fig.subplots(1, 2)
    t = plan.times
    a1.plot(t, plan.position_error * 1e3, label="tracking (vs line rotated by gamma)")
    a1.plot(t, plan.position_deviation * 1e3, "--", label="vs line")
    a2.plot(t, np.degrees(plan.rotation_error), label="tracking")
    a2.plot(t, np.degrees(plan.rotation_deviation), "--", label="vs line (includes gamma)")
    a2.plot(t, np.degrees(plan.gamma), ":", label="gamma")
    a1.set_ylabel("position error [mm]")
    a2.set_ylabel("rotation [deg]")
    _finish(a1)
    _finish(a2)
    fig.tight_layout()
    return fig


def plot_replan_velocity(plan: ReplanResult, *, fig: Any | None = None) -> Any:
    """Two panels (002 Figs. 14 and 20): the end effector's linear velocity [mm/s] and angular
    velocity [deg/s] (root frame) against time [s].  ``fig=None``: a new 11 x 4 inch figure.
    Returns the figure."""
    fig = new_figure(fig, (11, 4))
    a1, a2 = fig.subplots(1, 2)
    t = plan.times
    for k in range(3):
        a1.plot(t, plan.ee_velocity[:, k] * 1e3, label=f"v{'xyz'[k]}")
        a2.plot(t, np.degrees(plan.ee_velocity[:, 3 + k]), label=f"w{'xyz'[k]}")
    a1.set_ylabel("linear velocity [mm/s]")
    a2.set_ylabel("angular velocity [deg/s]")
    _finish(a1)
    _finish(a2)
    fig.tight_layout()
    return fig
