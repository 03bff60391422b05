"""Figures of a halt motion (000 §4-§5.2): global base torque vs k (Fig. 8), joint profiles
(Fig. 9), the base torque over the halt, and what a free spacecraft does during it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..planning.halt_motion import K_UNIT_SCALE, HaltMotion, base_torque_history, global_base_torque
from ._common import new_axes, new_figure

#: 1 deg/s^6 in rad/s^6 (k is shown in deg/s^6, 000's reading).
_K_DEG = K_UNIT_SCALE["deg/s^6"]


def k_label(res: HaltMotion) -> str:
    """What the reported k is: the optimum, or the least-violating k of an infeasible halt."""
    if not res.feasible:
        return "least-violating k (infeasible)"
    return "optimal k per joint" if res.per_joint else "optimal k*"


def k_text(res: HaltMotion, digits: int = 6) -> str:
    """The reported k in deg/s^6, ``digits`` significant digits, with the unit."""
    kd = np.atleast_1d(np.asarray(res.k, dtype=float) / _K_DEG) + 0.0  # + 0.0: no "-0"
    body = ", ".join(f"{v:.{digits}g}" for v in kd)
    return (f"[{body}]" if res.per_joint else body) + " deg/s^6"


def _k_star(res: HaltMotion) -> float:
    """The chosen k [rad/s^6] (the mean of the per-joint k of the vector solver)."""
    return float(np.mean(res.k)) if res.per_joint else float(res.k)


def global_torque_curve(res: HaltMotion, n: int = 201) -> tuple[np.ndarray, np.ndarray]:
    """The global base torque of eq. (32) over a k range covering 0, the chosen k and the
    feasible interval: ``(k (n,) [rad/s^6], torque (n,) [N m])`` (one shared k)."""
    k_star = _k_star(res)
    lo, hi = res.k_interval
    span = [0.0, max(0.01 * _K_DEG, 1.5 * abs(k_star))]
    if lo <= hi:
        span = [min(span[0], lo - 0.2 * (hi - lo)), max(span[1], hi + 0.2 * (hi - lo))]
    span = [min(span[0], 1.5 * k_star), span[1]]  # a negative k* is on the plot too
    grid = np.linspace(span[0], span[1], n)
    return grid, global_base_torque(res.problem, grid)


def plot_global_torque_vs_k(res: HaltMotion, *, ax: Any | None = None) -> Any:
    """000 Fig. 8: global base disturbance torque vs k, the feasible k band, the chosen k and
    the curve's own minimum when it lies elsewhere.  Returns the axis."""
    ax = new_axes(ax, (7, 4))
    p = res.problem
    label = k_label(res)
    k_star = _k_star(res)
    lo, hi = res.k_interval
    grid, tau = global_torque_curve(res)
    ax.plot(grid / _K_DEG, tau, label=r"$\bar\tau_b(k)$, shared k")
    stretches = [(lo, hi)] if res.k_segments is None else list(res.k_segments)
    if lo <= hi and res.k_segments is not None:  # speed and acceleration keep [lo, hi]; torques less
        ax.axvspan(lo / _K_DEG, hi / _K_DEG, color="0.5", alpha=0.12, label="speed and acceleration limits kept")
    if lo <= hi:
        for i, (a, b) in enumerate(stretches):
            ax.axvspan(
                a / _K_DEG,
                b / _K_DEG,
                color="g",
                alpha=0.15,
                label=None if i else f"feasible k: [{a / _K_DEG:.4g}, {b / _K_DEG:.4g}] deg/s$^6$"
                + (f" and {len(stretches) - 1} more" if len(stretches) > 1 else "")
                + (" (every limit, torques too)" if res.k_segments is not None else ""),
            )
        if res.k_segments == ():
            ax.plot([], [], " ", label="no k keeps the torque limits")
    else:  # a legend line saying so (no band to shade)
        ax.plot([], [], " ", label=f"no feasible k: every k breaks a limit (T = {p.T:g} s)")
    i_min = int(np.argmin(tau))
    star_text = f"{label} = {k_star / _K_DEG:.4g} deg/s$^6$"
    if res.per_joint:
        star_text = f"{label} (at their mean {k_star / _K_DEG:.4g} deg/s$^6$)"
    ax.plot([k_star / _K_DEG], [res.global_torque], "r*", ms=12, label=star_text)
    if abs(grid[i_min] - k_star) > 1.5 * (grid[1] - grid[0]):  # the curve's own minimum elsewhere
        inside = any(a <= grid[i_min] <= b for a, b in stretches) and lo <= hi
        where = "feasible" if inside else "breaks a limit"
        ax.plot(
            [grid[i_min] / _K_DEG],
            [tau[i_min]],
            "o",
            mfc="none",
            mec="k",
            ms=8,
            label=f"minimum on this range: k = {grid[i_min] / _K_DEG:.4g} deg/s$^6$ ({where})",
        )
    ax.set_xlabel("k [deg/s$^6$]")
    ax.set_ylabel("global base torque [N m]")
    verdict = "" if res.feasible else ", INFEASIBLE"
    chosen = "" if p.objective == "mean_torque" else f"; k* minimises the {p.objective.replace('_', ' ')}, not this curve"
    ax.set_title(f"global base disturbance torque vs k ({p.base} base{verdict}{chosen})", fontsize=9)
    ax.legend(fontsize=8)
    return ax


def plot_joint_profiles(res: HaltMotion, *, fig: Any | None = None) -> Any:
    """000 Fig. 9: angle, velocity and acceleration of every healthy joint over the halt, at
    the chosen k and at k = 0, with the limits.  Returns the figure (3 x n axes)."""
    p = res.problem
    n = p.dof
    fig = new_figure(fig, (3 * n, 7))
    label = k_label(res)
    t = p.times()
    q, dq, ddq = res.trajectory(t)
    q0_, dq0_, ddq0_ = p.trajectory(0.0, t)
    axes = fig.subplots(3, n, sharex=True, squeeze=False)
    for j in range(n):
        for row, (a, b, lim, ylabel) in enumerate(
            (
                (q, q0_, None, "angle [deg]"),
                (dq, dq0_, p.dq_max[j], "velocity [deg/s]"),
                (ddq, ddq0_, p.ddq_max[j], "acc. [deg/s$^2$]"),
            )
        ):
            ax = axes[row, j]
            ax.plot(t, np.degrees(a[:, j]), label=label)
            ax.plot(t, np.degrees(b[:, j]), "--", lw=0.8, label="k = 0")
            if lim is not None:
                for sgn in (-1, 1):
                    ax.axhline(sgn * math.degrees(lim), color="r", lw=0.6, label="limit" if sgn > 0 else None)
            if j == 0:
                ax.set_ylabel(ylabel)
        axes[0, j].set_title(f"joint {p.model.joint_numbers[j]}")
        axes[2, j].set_xlabel("t [s]")
    axes[1, 0].legend(fontsize=7)
    if not res.feasible:
        fig.suptitle(f"INFEASIBLE halt: {label} = {k_text(res, 4)}, limits broken", color="r")
    return fig


def plot_base_torque_vs_time(res: HaltMotion, *, ax: Any | None = None) -> Any:
    """Norm of the base disturbance torque over the halt, at k = 0 and at the chosen k (mean
    values in the legend).  Returns the axis."""
    ax = new_axes(ax, (7, 4))
    p = res.problem
    t = p.times()
    tb = base_torque_history(p, res.k, t, per_joint=res.per_joint)
    tb0 = base_torque_history(p, 0.0, t)
    ax.plot(t, np.linalg.norm(tb0, axis=-1), label=f"k = 0 (mean {res.global_torque_k0:.4g} N m)")
    ax.plot(
        t,
        np.linalg.norm(tb, axis=-1),
        label=f"{k_label(res)} = {k_text(res, 4).replace('^6', '$^6$')} (mean {res.global_torque:.4g} N m)",
    )
    ax.set_xlabel("t [s]")
    ax.set_ylabel(r"$\|\tau_b\|$ [N m]")
    if not res.feasible:
        ax.set_title("INFEASIBLE halt: every k breaks a limit", color="r")
    ax.legend(fontsize=8)
    return ax


def plot_spacecraft_response(
    response: Any, *, fig: Any | None = None, simulated: Any | None = None, simulator: str = "MuJoCo"
) -> Any:
    """The spacecraft during a free-floating motion
    (:class:`~jointlock.analysis.spacecraft.SpacecraftResponse`): attitude change [deg] and
    angular rate [deg/s] over time (left axis, right axis).  ``simulated``: the same motion
    replayed in a simulator (a response with ``t``, ``attitude_change_deg``,
    ``angular_velocity``: :meth:`jointlock.sim.Replay.simulated_response`), drawn dashed on top.
    Returns the figure."""
    fig = new_figure(fig, (7, 4))
    ax = fig.add_subplot()
    t = response.t
    ax.plot(t, response.attitude_change_deg, label="attitude change [deg]")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("attitude change from t = 0 [deg]")
    rate = ax.twinx()
    rate.plot(
        t, np.degrees(np.linalg.norm(response.angular_velocity, axis=-1)), color="C1", label="rate [deg/s]"
    )
    if simulated is not None:
        ax.plot(simulated.t, simulated.attitude_change_deg, "k--", lw=1, label=f"{simulator}: attitude change")
        rate.plot(simulated.t, np.degrees(np.linalg.norm(simulated.angular_velocity, axis=-1)), "k:", lw=1,
                  label=f"{simulator}: rate")  # fmt: skip
        ax.legend(fontsize=7, loc="upper left")
    rate.set_ylabel("angular rate [deg/s]", color="C1")
    ax.set_title(
        f"spacecraft: attitude change {response.final_attitude_change_deg:.3g} deg, peak {response.peak_rate_deg_s:.3g} deg/s, "
        f"drift {response.com_drift_m:.3g} m",
        fontsize=9,
    )
    return fig


def plot_actuator_loads(
    loads: Any, *, motor_limits: Any = None, brake_limits: Any = None, fig: Any | None = None
) -> Any:
    """Motor torques of the healthy joints (top) and brake torques of the locked joints
    (bottom) over a motion (:class:`~jointlock.analysis.actuators.ActuatorLoads`), with the
    limits (N m, ``inf``: none) as dashed lines.  Returns the figure."""
    fig = new_figure(fig, (7, 6))
    rows = 2 if loads.locked_numbers else 1
    axes = np.atleast_1d(fig.subplots(rows, 1, sharex=True))
    for ax, values, numbers, limits, what in (
        (axes[0], loads.motor, loads.joint_numbers, motor_limits, "motor"),
        (axes[-1] if rows == 2 else None, loads.brake, loads.locked_numbers, brake_limits, "brake (locked)"),
    ):
        if ax is None:
            continue
        for j, num in enumerate(numbers):
            line = ax.plot(loads.t, values[:, j], label=f"joint {num}")[0]
            if limits is not None and math.isfinite(limits[j]):
                for sgn in (-1, 1):
                    ax.axhline(sgn * limits[j], color=line.get_color(), ls="--", lw=0.7)
        ax.set_ylabel(f"{what} torque [N m]")
        ax.legend(fontsize=7, ncol=min(len(numbers), 4))
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(f"actuator torques over the motion ({loads.base} base; dashed: limits)", fontsize=9)
    return fig


def plot_clearance(clearance: Any, t: Any, *, margin: float = 0.0, ax: Any | None = None, pairs: int = 3) -> Any:
    """Clearance over a motion (:class:`~jointlock.collision.Clearance` of (n_t,) samples at
    times ``t`` [s]): the smallest over every checked pair (thick), the ``pairs`` pairs that
    come closest (thin), the clearance required (dashed) and contact (0 m, dotted).  Returns
    the axis."""
    ax = new_axes(ax, (7, 4))
    t = np.asarray(t, dtype=float)
    ax.plot(t, clearance.distance, lw=2.2, color="k", label="smallest")
    order: Any = np.argsort(clearance.pair_distance.min(axis=0))[:pairs] if clearance.names else []
    for p in order:
        ax.plot(t, clearance.pair_distance[:, p], lw=1.0, label=clearance.names[p])
    if margin > 0:
        ax.axhline(margin, color="tab:red", ls="--", lw=1.0, label=f"required {margin:g} m")
    ax.axhline(0.0, color="tab:red", ls=":", lw=1.0)
    at = int(np.argmin(clearance.distance)) if clearance.distance.size else 0
    worst = float(clearance.distance[at]) if clearance.distance.size else math.inf
    ax.set_xlabel("t [s]")
    ax.set_ylabel("clearance [m] (< 0: overlap)")
    ax.set_title(
        f"clearance over the halt: smallest {worst:+.3f} m ({clearance.pair_at((at,)) if clearance.names else 'no pair'}, "
        f"t = {t[at]:.3g} s)",
        fontsize=9,
    )
    ax.legend(fontsize=7)
    return ax
