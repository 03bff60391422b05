"""000's defaults: halt7 with joint 4 locked at 0 deg gets 000 §5.2's state, limits and halt time."""

from __future__ import annotations

import math
from typing import Any


def _is_000_failure(robot: str, fail: dict[str, Any]) -> bool:
    """halt7 with joint 4 locked at 0 deg: the failure 000's state, limits and T belong to."""
    angle = fail.get("angle_deg")
    if fail.get("also_locked_deg"):
        return False
    return robot == "halt7" and fail.get("joint") == 4 and angle is not None and math.isclose(angle, 0.0, abs_tol=1e-9)


def _defaults_000(out: dict[str, Any], jobs: tuple[str, ...], model: Any) -> None:
    """halt7 with joint 4 locked: 000 §5's state and limits where the file gives none."""
    fail = out["failure"]
    if not _is_000_failure(model.name, fail) or not ({"halt", "halt_config"} & set(jobs)):
        return
    from ..papers.p000 import SCENARIO as PAPER_SCENARIO

    for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
        if out["state"][key] is None:
            out["state"][key] = list(PAPER_SCENARIO[key])
    for key in ("vmax_deg", "amax_deg"):
        if out["limits"][key] is None:
            out["limits"][key] = PAPER_SCENARIO[key]
    if "halt" in jobs and out["halt"]["T"] is None:
        out["halt"]["T"] = PAPER_SCENARIO["T"]
