"""Figures of the velocity-jump study (seed 001, ``jointlock jump``).

Jumps and joint rates are drawn in deg/s, kappa in rad^2/(s m^3), deviations in mm.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..model import ArmModel
from ..planning.jump import KappaFit, KappaSearch, Trajectory, Verification
from ._common import new_axes, new_figure

#: Unit of kappa: qdot [rad/s] = kappa * grad w, w = sqrt(det(J J^T)) of the 3 x n position
#: Jacobian [m^3], grad w [m^3/rad] (docs/jump.md).
KAPPA_UNIT = "rad^2/(s m^3)"


def plot_objective_vs_kappa(search: KappaSearch, index: int = 0, *, title: str = "", ax: Any | None = None) -> Any:
    """The jump ``||dqdot||`` [deg/s] over the searched kappa grid at failure time
    ``search.fail_times[index]``: feasible grid points, those that break a limit, the optimum.
    Returns the axis."""
    ax = new_axes(ax, (6, 3.6))
    g, obj = search.kappa_grid, np.degrees(search.objective[:, index])
    feas = search.feasible[:, index]
    ax.plot(g, obj, "-", color="0.6")
    ax.plot(g[feas], obj[feas], "o", label="feasible")
    ax.plot(g[~feas], obj[~feas], "x", color="r", label="breaks a limit")
    if np.isfinite(search.kappa_opt[index]):
        ax.plot(search.kappa_opt[index], np.degrees(search.objective_opt[index]), "*", ms=12, label="optimum")
    ax.set_xlabel(f"kappa [{KAPPA_UNIT}]")
    ax.set_ylabel("||dq jump|| [deg/s]")
    ax.set_title(title)
    ax.legend()
    return ax


def plot_joint_rates(
    model: ArmModel,
    lock_joint: int,
    uncompensated: Trajectory,
    compensated: Trajectory,
    fail_time: float,
    *,
    fig: Any | None = None,
) -> Any:
    """Joint rates [deg/s] of the locking joint and of the next one, with kappa = 0 and with
    the compensation, the failure time [s] marked; two axes side by side.  Returns the figure."""
    fig = new_figure(fig, (10, 3.6))
    axes = fig.subplots(1, 2)
    t = uncompensated.t[:-1]
    j = model.index_of(lock_joint)
    other = (j + 1) % model.dof
    for ax, col in zip(axes, (j, other)):
        ax.step(t, np.degrees(uncompensated.qd[:, col]), where="post", label="kappa = 0")
        ax.step(t, np.degrees(compensated.qd[:, col]), where="post", label="compensated")
        ax.axvline(fail_time, color="k", lw=0.6, ls=":")
        ax.set_title(f"joint {model.joint_numbers[col]}" + (" (locked)" if col == j else ""))
        ax.set_xlabel("t [s]")
        ax.set_ylabel("joint rate [deg/s]")
        ax.legend()
    return fig


def plot_position_deviation(
    uncompensated: Trajectory, compensated: Trajectory, fail_time: float, eps: float, *, ax: Any | None = None
) -> Any:
    """Position deviation ``||x - x_nom||`` [mm] over time with kappa = 0 and with the
    compensation, the threshold ``eps`` [m] and the failure time [s] marked.  Returns the axis."""
    ax = new_axes(ax, (6, 3.6))
    ax.plot(uncompensated.t, 1e3 * uncompensated.deviation, label="kappa = 0")
    ax.plot(compensated.t, 1e3 * compensated.deviation, label="compensated")
    ax.axhline(1e3 * eps, color="r", ls="--", label="threshold")
    ax.axvline(fail_time, color="k", lw=0.6, ls=":")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("||x - x_nom|| [mm]")
    ax.legend()
    return ax


def plot_kappa_fit(search: KappaSearch, fit: KappaFit, duration: float, *, ax: Any | None = None) -> Any:
    """The optimal kappa at the sampled failure times, the single polynomial and the piecewise
    kappa(t) over ``[0, duration]`` [s]; segment points (dotted) and breaks (dashed) marked.
    Returns the axis."""
    ax = new_axes(ax, (6, 3.6))
    ax.plot(search.fail_times, search.kappa_opt, "o", label="optimal kappa (samples)")
    tt = np.linspace(0, duration, 400)
    ax.plot(tt, fit.polynomial(tt), "--", color="0.5", label=f"polynomial, order {fit.order}")
    ax.plot(tt, fit(tt), "-", label="kappa(t), piecewise")
    for tp in fit.segment_points:
        if np.isfinite(tp):
            ax.axvline(tp, color="k", lw=0.6, ls=":")
    for tb in fit.breaks:
        ax.axvline(tb, color="r", lw=0.6, ls="--")
    ax.set_xlabel("failure time [s]")
    ax.set_ylabel(f"kappa [{KAPPA_UNIT}]")
    ax.legend()
    return ax


def plot_jump_vs_failure_time(
    verification: Verification, fixed: Verification | None = None, *, ax: Any | None = None
) -> Any:
    """The jump ``||dqdot||`` [deg/s] per failure time with kappa = 0 and with kappa(t) (and
    with the fixed kappa(t) when ``fixed`` is given).  Returns the axis."""
    ax = new_axes(ax, (7, 3.6))
    ax.plot(verification.t, np.degrees(verification.jump_before), label="kappa = 0")
    ax.plot(verification.t, np.degrees(verification.jump_after), label="kappa(t)")
    if fixed is not None:
        ax.plot(fixed.t, np.degrees(fixed.jump_after), ":", label=f"kappa(t), {fixed.fix}")
    ax.set_xlabel("failure time [s]")
    ax.set_ylabel("||dq jump|| [deg/s]")
    ax.legend()
    return ax


__all__ = [
    "KAPPA_UNIT",
    "plot_joint_rates",
    "plot_jump_vs_failure_time",
    "plot_kappa_fit",
    "plot_objective_vs_kappa",
    "plot_position_deviation",
]
