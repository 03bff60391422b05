"""Can the task still be finished after a joint locks? (issue 28, item 3)

A planned motion (:class:`~jointlock.planning.task.Task`) of the whole arm is followed until a
joint locks at ``t_fail``, at the angle the task had it then.  For each remaining waypoint (a
waypoint task) or each remaining sample time (a sampled task), the end-effector pose the plan
would have reached is asked of the crippled arm: :func:`jointlock.ik.solve_ik` on the locked
model (002's closed form where the arm's family allows it, Levenberg-Marquardt otherwise; a
redundant arm keeps its remaining joints), with a tolerance.  The answer: which poses are
reachable, how far the nearest reachable pose is from each unreachable one, and the first time
the task cannot be followed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigurationError
from ..kinematics import ee_pose
from ..locking import lock
from ..model import ArmModel, FloatArray
from .task import Task

__all__ = ["COMPLETION_TOLERANCE", "TaskCompletion", "task_completion"]

#: A pose counts as reached within 1 mm and 1 mrad (0.057 deg) by default.
COMPLETION_TOLERANCE = (1e-3, 1e-3)


@dataclass(frozen=True, eq=False)  # arrays inside
class TaskCompletion:
    """Whether the rest of a task is reachable by the arm with ``joint`` locked at ``angle``.

    Attributes
    ----------
    joint, angle, t_fail
        The locked joint (1-based), its angle [rad] (the task's at ``t_fail``) and the instant [s].
    times
        (m,) the remaining waypoints' times (or sample times) after ``t_fail`` [s].
    reachable
        (m,) the pose the task reaches then is reachable by the locked arm within ``tolerance``.
    position_error, rotation_error
        (m,) distance [m] and angle [rad] from each pose to the nearest pose the locked arm
        reaches (0 when reachable exactly).
    tolerance
        ``(position [m], rotation [rad])``.
    """

    joint: int
    angle: float
    t_fail: float
    times: FloatArray
    reachable: np.ndarray
    position_error: FloatArray
    rotation_error: FloatArray
    tolerance: tuple[float, float]

    @property
    def completable(self) -> bool:
        """Every remaining pose is reachable."""
        return bool(np.all(self.reachable))

    @property
    def first_unreachable_s(self) -> float | None:
        """The first time [s] whose pose the locked arm cannot reach, None when none."""
        bad = np.flatnonzero(~self.reachable)
        return float(self.times[bad[0]]) if bad.size else None

    @property
    def share_reachable(self) -> float:
        return float(np.mean(self.reachable)) if self.reachable.size else 1.0

    def summary(self) -> list[str]:
        head = (
            f"task completion with joint {self.joint} locked at {math.degrees(self.angle):.4g} deg (t = {self.t_fail:g} s): "
        )
        if self.completable:
            return [head + f"every remaining pose reachable ({self.times.size} checked, within "
                    f"{1e3 * self.tolerance[0]:g} mm and {math.degrees(self.tolerance[1]):.3g} deg)"]  # fmt: skip
        k = int(np.flatnonzero(~self.reachable)[0])
        return [
            head + f"NOT COMPLETABLE: the pose at t = {self.times[k]:g} s is out of reach first "
            f"({1e3 * self.position_error[k]:.3g} mm, {math.degrees(self.rotation_error[k]):.3g} deg from the nearest "
            f"reachable); {int(np.sum(self.reachable))} of {self.times.size} remaining poses reachable"
        ]

    def to_dict(self) -> dict[str, Any]:
        return {
            "joint": self.joint,
            "angle_deg": math.degrees(self.angle),
            "t_fail_s": self.t_fail,
            "completable": self.completable,
            "first_unreachable_s": self.first_unreachable_s,
            "share_reachable": self.share_reachable,
            "times_s": self.times.tolist(),
            "reachable": self.reachable.tolist(),
            "position_error_m": self.position_error.tolist(),
            "rotation_error_rad": self.rotation_error.tolist(),
            "tolerance": list(self.tolerance),
        }


def task_completion(
    model: ArmModel,
    task: Task,
    joint: int,
    t_fail: float,
    *,
    samples: int = 21,
    tolerance: tuple[float, float] = COMPLETION_TOLERANCE,
    rng: int = 0,
) -> TaskCompletion:
    """Check the rest of ``task`` on ``model`` (the whole arm) with ``joint`` locked at
    ``t_fail`` (see the module docstring): a waypoint task's remaining waypoints, a sampled
    task's ``samples`` evenly spaced times after ``t_fail`` (its end included).

    Raises
    ------
    ConfigurationError
        A joint outside the arm, a time outside the task, a bad tolerance or sample count.
    """
    from ..ik import solve_ik

    task.check(model)
    if isinstance(joint, bool) or not isinstance(joint, int) or not 1 <= joint <= model.dof:
        raise ConfigurationError(f"joint must be a joint number 1..{model.dof} of {model.name}; got {joint!r}")
    if not (math.isfinite(t_fail) and task.start <= t_fail <= task.end):
        raise ConfigurationError(f"t_fail must lie in the task, [{task.start:g}, {task.end:g}] s; got {t_fail!r}")
    pos_tol, rot_tol = (float(v) for v in tolerance)
    if not (pos_tol >= 0 and rot_tol >= 0 and math.isfinite(pos_tol) and math.isfinite(rot_tol)):
        raise ConfigurationError(f"tolerance must be (position [m], rotation [rad]), each >= 0; got {tolerance!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ConfigurationError(f"samples must be an integer >= 1; got {samples!r}")
    if task.kind == "waypoints":
        times = task.t[task.t > t_fail]
    else:
        times = np.linspace(t_fail, task.end, samples + 1)[1:] if t_fail < task.end else np.zeros(0)
    q_fail = task.state(t_fail)[0]
    angle = float(q_fail[joint - 1])
    crippled = lock(model, joint, angle)
    reachable = np.zeros(times.size, dtype=bool)
    pos_err = np.zeros(times.size)
    rot_err = np.zeros(times.size)
    if times.size:
        poses = ee_pose(model, task.state(times)[0])
        for k, target in enumerate(poses):
            result = solve_ik(crippled, target, rng=rng, tolerance=(pos_tol, rot_tol))
            reachable[k] = result.reachable
            if not result.reachable and result.nearest is not None:
                pos_err[k], rot_err[k] = result.nearest.position_error, result.nearest.rotation_error
    return TaskCompletion(joint, angle, float(t_fail), times, reachable, pos_err, rot_err, (pos_tol, rot_tol))
