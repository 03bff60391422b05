"""The motions of a job's result as :class:`~jointlock.plots.motion.ArmMotion` (what the 3-D
animation draws and ``motion.json`` holds): the halt, the jump study's two runs and the
re-planned path.  Each draws the full arm (locked joints at their angles, marked from their
lock) in the spacecraft's first frame, the spacecraft turning and drifting when it is free."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..analysis.spacecraft import SpacecraftResponse
from ..model import ArmModel, FloatArray
from ..plots.motion import ArmMotion, drawn_arm

if TYPE_CHECKING:
    from .halt._result import HaltPlan
    from .jump._result import JumpJobResult
    from .replan import ReplanJobResult

#: At most this many samples per motion in ``motion.json`` (the animation shows at most 120).
MOTION_SAMPLES = 401


def _full(model: ArmModel, q: FloatArray) -> FloatArray:
    return model.expand(q) if drawn_arm(model) is not model else np.asarray(q, dtype=float)


def _base(model: ArmModel, response: SpacecraftResponse | None) -> dict[str, Any]:
    """``base_position`` and ``base_attitude`` of :class:`ArmMotion` (none for a held base)."""
    if response is None:
        return {}
    return {"base_position": response.root_positions(model.root_body.com), "base_attitude": response.attitude}


def halt_motions(plan: HaltPlan) -> tuple[ArmModel, list[ArmMotion]]:
    """The halt from the failure state to rest at the halt configuration; the locked joints
    locked throughout; the spacecraft free only with ``base="floating"`` (000's fixed-base
    torque holds it)."""
    p = plan.problem
    t = p.times(min(MOTION_SAMPLES, max(p.n_samples, 2)))
    q, dq, _ = plan.motion.trajectory(t)
    response = plan.spacecraft_response(t.size) if p.base == "floating" else None  # on the grid t
    locks = tuple((lj.number, float(t[0])) for lj in p.model.locked) if drawn_arm(p.model) is not p.model else ()
    label = "halt" if plan.motion.feasible else "halt (INFEASIBLE: least-violating k)"
    motion = ArmMotion(label, t, _full(p.model, q), locks, **_base(p.model, response))
    return drawn_arm(p.model), [motion]


def jump_motions(result: JumpJobResult) -> tuple[ArmModel, list[ArmMotion]]:
    """The jump study's two runs, without and with compensation, the joint locking at the
    failure instant; the nominal end-effector path as the target."""
    r0, r1, t_fail = result.runs()
    responses = result.spacecraft_responses() or {}
    lock = ((int(result.task.lock_joint), float(t_fail)),)
    motions = []
    for label, run, key in (("kappa = 0", r0, "uncompensated"), ("compensated", r1, "compensated")):
        step = max(1, math.ceil(run.t.size / MOTION_SAMPLES))
        keep = np.unique(np.r_[np.arange(0, run.t.size, step), run.t.size - 1, np.searchsorted(run.t, t_fail)])
        base = _base(result.model, responses.get(key))
        motions.append(
            ArmMotion(
                label,
                run.t[keep],
                run.q[keep],
                lock,
                **{k: v[keep] for k, v in base.items()},
                target=run.x_nom[keep],
                target_label="nominal path",
            )
        )
    return result.model, motions


def replan_motions(result: ReplanJobResult) -> tuple[ArmModel, list[ArmMotion]]:
    """The locked arm through the re-planned waypoints, the straight target path beside it
    (drawn in the spacecraft's first frame: a free spacecraft that turns carries the end
    effector off it by what it turned)."""
    plan = result.plan
    model = result.model
    if model is None:
        raise ValueError("this re-plan result has no model to draw (built without one)")
    locks = ((int(plan.joint), float(plan.times[0])),)
    base = _base(model, result.spacecraft_response())
    arm = drawn_arm(model)
    q = plan.q_full if arm.dof == plan.q_full.shape[1] else plan.q
    motion = ArmMotion("re-planned", plan.times, q, locks if arm.dof == plan.q_full.shape[1] else (), **base,
                       target=plan.target[:, :3, 3], target_label="target path")  # fmt: skip
    return arm, [motion]
