"""The words of :class:`~jointlock.jobs.halt.HaltPlan`: how its summary names objectives,
moment points, margins, limits and violations, and 000's printed numbers."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...papers import p000
from ...planning.halt_motion import HaltMotion
from .._common import AT_LIMIT

#: How the summary names what k minimises (:attr:`HaltProblem.objective`).
OBJECTIVE_TEXT = {
    "mean_torque": "time-averaged base torque (000 eq. 32)",
    "peak_torque": "peak base torque",
    "attitude_change": "the free spacecraft's attitude change at the end",
}

#: How the summary names the base torque's point (:attr:`HaltProblem.moment_about`).
MOMENT_TEXT = {
    "spacecraft_com": "the spacecraft's centre of mass",
    "joint1": "joint 1's mount (the root frame's origin)",
}


def _margin_text(margin: float) -> str:
    """A limit's margin in words: "12 %" kept, "at the limit" (< :data:`AT_LIMIT`), "broken"."""
    if margin < -1e-9:
        return "broken"
    if margin < AT_LIMIT:
        return "at the limit"
    return f"{100 * margin:.0f} %"


def _torque_limit_text(limit: float, margin: float) -> str:
    """``"(no limit)"`` or ``"(300, 12 %)"``."""
    return "(no limit)" if not math.isfinite(limit) else f"({limit:.6g}, {_margin_text(margin)})"


def _none_for_nan(values: np.ndarray) -> list[float | None]:
    return [None if math.isnan(v) else float(v) for v in values]


def _none_for_inf(values: np.ndarray | None) -> list[float | None] | None:
    return None if values is None else [float(v) if math.isfinite(v) else None for v in values]


def _violation(v: Any) -> dict[str, Any]:
    """A violation in people's units: ``*_deg`` for angles and rates (deg, deg/s, deg/s^2),
    ``*_Nm`` for motor and brake torques."""
    value, limit, excess, unit = v.display
    suffix = "Nm" if unit == "N m" else "deg"
    return {
        "joint": v.joint,
        "limit": v.kind,
        f"limit_value_{suffix}": limit,
        f"value_{suffix}": value,
        f"excess_{suffix}": excess,
        "time_s": v.time,
    }


def _printed_text() -> str:
    """000 §5.2's printed results (:data:`jointlock.papers.p000.HALT_RESULTS`) as one line:
    ``"000 printed: k = 0.0018, 22.25 -> 15.55 N m (30.1 %)"``."""
    r = p000.HALT_RESULTS
    return (
        f"000 printed: k = {r['k']:g}, {r['global_torque_k0_Nm']:g} -> {r['global_torque_Nm']:g} N m "
        f"({100 * r['reduction']:.1f} %)"
    )


def _jacobian_text(hcom_base: str) -> str:
    if hcom_base == "fixed":  # a robot without a spacecraft: J_F is the fixed-base one
        return "generalized Jacobian, which for this fixed-base model is the fixed-base Jacobian"
    return "free-floating arm's generalized Jacobian J_F (000 §3.1.2)"


def _change_text(res: HaltMotion) -> str:
    """The torque change from k = 0 to the chosen k, in words."""
    if math.isnan(res.reduction):
        return "reduction n/a: no torque at k = 0"
    if res.reduction >= 0:
        return f"{100 * res.reduction:.1f} % lower"
    if res.violations_k0:
        return f"{-100 * res.reduction:.1f} % higher: k = 0 breaks a limit"
    return f"{-100 * res.reduction:.1f} % higher"


def limits_table(
    numbers: Any,
    velocity: tuple[Any, Any],
    acceleration: tuple[Any, Any],
    margins: dict[str, Any],
    loads: Any,
    limits: Any,
) -> list[str]:
    """The summary's table: per healthy joint the peak speed, acceleration and motor torque, each
    with its limit and margin; then one line per locked joint's brake.  ``velocity`` and
    ``acceleration`` are ``(peaks, limits)`` [deg/s, deg/s^2]; ``loads`` an
    :class:`~jointlock.analysis.actuators.ActuatorLoads` or None; ``limits`` the
    :class:`JointLimits` (its torque and brake limits [N m], None for none)."""
    lines = [
        "",
        "joint   peak |dq| [deg/s] (limit, margin)   peak |ddq| [deg/s^2] (limit, margin)   "
        "peak |tau| [N m] (limit, margin)",
    ]
    tau_lim = limits.torque if limits.torque is not None else np.full(len(numbers), np.inf)
    for j, num in enumerate(numbers):
        v_text = f"({velocity[1][j]:.6g}, {_margin_text(margins['velocity'][j])})"
        a_text = f"({acceleration[1][j]:.6g}, {_margin_text(margins['acceleration'][j])})"
        t_text = (
            ""
            if loads is None
            else f"{loads.peak_motor[j]:10.1f} {_torque_limit_text(tau_lim[j], margins['torque'][j])}"
        )
        lines.append(
            f"{num:>5}   {velocity[0][j]:10.3f} {v_text:<24}  {acceleration[0][j]:10.3f} {a_text:<24}  {t_text}"
        )
    if loads is not None:
        brake_lim = limits.brake if limits.brake is not None else np.full(len(loads.locked_numbers), np.inf)
        for j, num in enumerate(loads.locked_numbers):
            lines.append(
                f"{num:>5}   locked: brake holds peak {loads.peak_brake[j]:.1f} N m "
                f"{_torque_limit_text(brake_lim[j], margins['brake'][j])}"
            )
    return lines
