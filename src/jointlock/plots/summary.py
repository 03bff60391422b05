"""Summary figures of a scenario run's report: one per job, drawn from plain arrays."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._common import new_axes


def plot_jump_before_after(
    failure_times: ArrayLike, jump_before: ArrayLike, jump_after: ArrayLike, *, ax: Any | None = None
) -> Any:
    """2-norm of the joint-rate jump [rad/s] (plotted in deg/s) vs failure time [s], without
    compensation and with the fitted kappa(t) (001).  Returns the axis."""
    ax = new_axes(ax, (7, 3.6))
    ax.plot(failure_times, np.degrees(np.asarray(jump_before, dtype=float)), label="kappa = 0")
    ax.plot(failure_times, np.degrees(np.asarray(jump_after, dtype=float)), label="kappa(t)")
    ax.set_xlabel("failure time [s]")
    ax.set_ylabel("||joint-rate jump|| [deg/s]")
    ax.legend()
    return ax


def plot_halt_base_torque(
    t: ArrayLike, tau_b: ArrayLike, tau_b_k0: ArrayLike, *, label: str, ax: Any | None = None
) -> Any:
    """Norm of the base disturbance torque (m, 3) [N m] over the halt times ``t`` (m,) [s], at
    k = 0 and at the chosen k (``label``).  Returns the axis."""
    ax = new_axes(ax, (7, 3.6))
    ax.plot(t, np.linalg.norm(np.asarray(tau_b_k0), axis=-1), label="k = 0")
    ax.plot(t, np.linalg.norm(np.asarray(tau_b), axis=-1), label=label)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("||base torque|| [N m]")
    ax.legend()
    return ax


def plot_replan_error(
    time_s: ArrayLike, position_error_m: ArrayLike, gamma_deg: ArrayLike, *, ax: Any | None = None
) -> Any:
    """Tracking position error [m] (plotted in mm) and the tolerance angle gamma [deg] along a
    re-planned line (002).  Returns the axis."""
    ax = new_axes(ax, (7, 3.6))
    ax.plot(time_s, 1e3 * np.asarray(position_error_m, dtype=float), label="position [mm]")
    ax.plot(time_s, gamma_deg, label="gamma [deg]")
    ax.set_xlabel("t [s]")
    ax.legend()
    return ax
