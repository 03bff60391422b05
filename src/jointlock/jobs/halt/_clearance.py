"""What a halt's clearance report says (issue 27): the halt motion's distances on the constraint
grid and between its samples, each pair held to the smaller of the clearance required (0 for a
mounted pair) and its distance at the failure; the summary's first line when the halt comes
closer; and the smallest halt time that keeps the clearance as the summary says it.

:class:`~jointlock.jobs.halt.HaltPlan` computes the distances
(:meth:`~jointlock.jobs.halt.HaltPlan.clearance`) and keeps the report; these functions only read
them.
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np

from ...collision import Clearance, ClearanceSettings
from ...planning.halt_motion import HaltMotion, clear_T_range
from ...sweep import swept_clearance


def clearance_report(motion: HaltMotion, settings: ClearanceSettings, sampled: Clearance) -> dict[str, Any]:
    """The clearance of the halt ``motion`` as ``HaltPlan.to_dict()["clearance"]`` gives it, from
    its distances ``sampled`` on the constraint grid (``n_check`` samples) and the certified bound
    between them (:func:`jointlock.sweep.swept_clearance`)."""
    problem = motion.problem
    t = problem.times(problem.n_check)
    d = sampled.pair_distance  # (n_check, P)
    # a pair already closer than allowed at the failure may not come closer still
    allowed = np.where(sampled.mounted_pairs, 0.0, settings.margin)
    floor = np.minimum(allowed, d[0])
    shortfall = floor - d  # > 0: closer than allowed, and than at the start
    between = swept_clearance(
        problem.model, motion.trajectory, t, floor, keep_out=settings.keep_out, sampled=(*motion.check_trajectory(), d)
    )
    collides = bool(np.any(shortfall > 0))
    at, pair = np.unravel_index(int(np.argmax(shortfall) if collides else np.argmin(d)), d.shape)
    start_pair = int(np.argmax(allowed - d[0]))
    swept_pair = between.worst()
    return {
        "halt_configuration_m": float(sampled.distance[-1]),
        "halt_configuration_pair": sampled.pair_at((sampled.distance.size - 1,)),
        "start_m": float(d[0, start_pair]),
        "start_pair": sampled.names[start_pair],
        "start_closer_than_allowed": bool(allowed[start_pair] > d[0, start_pair]),
        "motion_min_m": float(d[at, pair]),
        "motion_min_pair": sampled.names[pair],
        "motion_min_time_s": float(t[at]),
        "between_samples_min_m": float(between.lower_bound[swept_pair]),
        "between_samples_pair": sampled.names[swept_pair],
        "between_samples_time_s": float(between.lower_bound_time[swept_pair]),
        "between_samples_clear": bool(between.shortfall <= 0),
        "tunnelling_tolerance_m": between.tolerance,
        "refined_samples": between.refined_samples,
        "required_m": settings.min_m,
        "collides": collides or bool(between.shortfall > 0),
        "collides_at_samples": collides,
        "worst_shortfall_m": float(max(shortfall.max(), between.shortfall, 0.0)),
        "samples": int(sampled.distance.size),
        "mounted_pairs": list(sampled.mounted),
    }


def collision_line(data: dict[str, Any] | None, settings: ClearanceSettings, robot: str) -> list[str]:
    """The summary's first line when the halt (``data``: :func:`clearance_report`) comes closer
    than required or starts closer; none otherwise."""
    if data is None or not (data["collides"] or data["start_closer_than_allowed"]):
        return []

    def reach(d: float) -> str:
        return f"{-d:.3f} m into" if d < 0 else f"within {d:.3f} m of"

    head = "COLLIDES" if data["collides"] else "CLEARANCE"
    minimum = settings.min_m
    required = "clearance reported, not required" if minimum is None else f"required {minimum:g} m"
    text = f"{head}: "
    if data["start_closer_than_allowed"]:
        text += (
            f"the state at failure already reaches {reach(data['start_m'])} {data['start_pair']} ({required}: "
            f"check the state, or the collision geometry: {robot}'s is documented with its factory); "
        )
    if data["collides_at_samples"]:
        text += f"the halt reaches {reach(data['motion_min_m'])} {data['motion_min_pair']} at t = {data['motion_min_time_s']:.3g} s"
    elif data["collides"]:
        text += (
            f"between its samples the halt may reach {reach(data['between_samples_min_m'])} "
            f"{data['between_samples_pair']} near t = {data['between_samples_time_s']:.3g} s (a bound on how far "
            "the links can move between two samples)"
        )
    else:
        text += "the halt comes no closer"
    text += f"; the halt configuration keeps {data['halt_configuration_m']:+.3f} m ({data['halt_configuration_pair']})"
    return [text]


def minimum_T_clear_lines(motion: HaltMotion, margin: float, minimum_T_clear: float | None) -> list[str]:
    """The summary's line on the smallest halt time that keeps the clearance ``margin`` [m] as
    well (``minimum_T_clear`` [s], None: none in the range searched)."""
    if minimum_T_clear is None:
        longest = clear_T_range(motion.problem.T, cast(float, motion.minimum_T))
        return [
            f"  no halt time up to {longest:.3g} s keeps the clearance ({margin:g} m) as well (for this halt configuration)"
        ]
    return [f"  keeping the clearance ({margin:g} m) as well: T = {minimum_T_clear:.3f} s"]
