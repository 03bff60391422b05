"""One ``k`` per joint by Powell's method within each joint's interval: the search shared by the
vector solver (:mod:`._solve`) and its clearance-keeping variant (:mod:`._clearance_limits`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ...model import FloatArray

#: Powell's stopping tolerances (on the scaled variables, and on the objective).
PER_JOINT_XTOL = 1e-6
PER_JOINT_FTOL = 1e-10


def powell_per_joint(
    value: Callable[[FloatArray], float], start: FloatArray, intervals: FloatArray, scale: float
) -> tuple[FloatArray, dict[str, Any]]:
    """Minimise ``value(k)`` over the per-joint ``k`` (n,) [rad/s^6], each within its row of
    ``intervals`` (n, 2), from ``start`` (n,); the variables are ``k / scale`` (so that Powell's
    tolerances are relative to the intervals' width).  Returns the result clipped to the
    intervals and scipy's record."""
    from scipy.optimize import minimize  # on first use (slow to import)

    res = minimize(
        lambda x: value(x * scale),
        start / scale,
        method="Powell",
        bounds=[(float(a) / scale, float(b) / scale) for a, b in intervals],
        options={"xtol": PER_JOINT_XTOL, "ftol": PER_JOINT_FTOL},
    )
    k = np.clip(res.x * scale, intervals[:, 0], intervals[:, 1])
    return k, {"method": "Powell", "nfev": int(res.nfev), "message": str(res.message)}
