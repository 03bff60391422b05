"""Plain-language report of an infeasible halt."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._constants import K_UNIT_SCALE
from ._feasibility import _start_breaks_limits

if TYPE_CHECKING:
    from ._solve import HaltMotion


def infeasibility_message(result: HaltMotion, *, k_unit: str = "deg/s^6") -> str:
    """Plain-language verdict for an infeasible halt: which joint, which limit, by how much,
    and the smallest halt time with a feasible ``k``."""
    scale = K_UNIT_SCALE[k_unit]
    p = result.problem
    k = ", ".join(f"{v:.6g}" for v in np.atleast_1d(np.asarray(result.k, dtype=float) / scale))
    lines = [
        f"no k satisfies the limits for a {p.T:g} s halt: every value of k breaks at least one limit.",
        f"least-violating k = {k} {k_unit}; there:",
    ]
    lines += ["  " + v.describe() for v in result.violations[:6]]
    torque = any(v.kind in ("torque", "brake") for v in result.violations)
    if torque:
        lines[0] = (
            f"no k keeps the torque limits for a {p.T:g} s halt: every k within the speed and acceleration "
            "limits breaks a motor or brake torque limit."
        )
    if result.minimum_T is not None:
        lines.append(f"smallest halt time with a feasible k: T = {result.minimum_T:.3f} s")
    elif torque:
        lines.append(f"no halt time up to {max(10 * p.T, 120.0):g} s keeps the torque limits (for this halt configuration)")
    elif _start_breaks_limits(p):
        lines.append("the state at failure already breaks a limit (at t = 0): no halt time or k helps")
    else:
        lines.append(f"no halt time up to {max(10 * p.T, 120.0):g} s has a feasible k")
    return "\n".join(lines)
