"""Straight-line Cartesian re-planning of the locked arm (seed 002 step 6, eqs. 19-20):
:func:`replan_line` and the line's waypoints (see :mod:`jointlock.planning.replan`)."""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ConfigurationError, ModelError
from ...ik import (
    EXACT_POSITION_TOL,
    EXACT_ROTATION_TOL,
    Puma6Geometry,
    _as_poses,
    ik_closed_form,
    puma6_geometry,
)
from ...kinematics import ee_pose
from ...model import ArmModel, FloatArray
from ...spatial import axis_angle_rotation, pose_error, rotation_log
from ._gamma import _pick_branch, tool_x_rotation
from ._path import DEFAULT_STEP_WEIGHT, PATH_GAMMA_STEP, _continuous_plan
from ._pointwise import _pointwise_absorbed, _pointwise_plan
from ._result import ReplanResult, StepFlag

#: Default jump threshold: this many times the median largest joint step ...
JUMP_MEDIAN_FACTOR = 5.0
#: ... and at least this [rad] ...
JUMP_MIN_STEP = math.radians(2.0)
#: ... and at most this [rad]: a joint that moves more between two waypoints is flagged even
#: when every step is that large (a plan too coarse to follow the line: few waypoints).
JUMP_MAX_STEP = math.radians(30.0)


def line_waypoints(start: ArrayLike, goal: ArrayLike, steps: int) -> FloatArray:
    """002 eqs. (19)-(20): ``steps`` interior points plus both ends, (steps + 2, 4, 4).

    Positions are ``p_a + i (p_c - p_a) / (N + 1)``, ``i = 0..N+1``.  002 interpolates only
    the position; the orientation here follows the geodesic (``R_a exp(s log(R_a^T R_c))``).
    """
    a, c = _as_poses(start, "start"), _as_poses(goal, "goal")
    if steps < 0:
        raise ConfigurationError(f"steps must be >= 0; got {steps}")
    s = np.arange(steps + 2) / (steps + 1)
    rel = rotation_log(a[:3, :3].T @ c[:3, :3])
    angle = np.linalg.norm(rel)
    axis = rel / angle if angle > 0 else np.array([1.0, 0.0, 0.0])
    rots = a[:3, :3] @ axis_angle_rotation(axis, s * angle)
    out = np.zeros((s.size, 4, 4))
    out[:, :3, :3] = rots
    out[:, :3, 3] = a[:3, 3] + s[:, None] * (c[:3, 3] - a[:3, 3])
    out[:, 3, 3] = 1.0
    return out


# Over 100 lines: 71 are the docstring (both planning methods); the body is ~60 lines.
def replan_line(
    model: ArmModel,
    start: ArrayLike,
    goal: ArrayLike,
    *,
    steps: int = 40,
    cycle: float = 0.25,
    gamma_tolerance: float = 0.0,
    q_ref: ArrayLike | None = None,
    branch: int | None = None,
    gamma_step: float = math.radians(0.05),
    method: str = "continuous",
    step_weight: float = DEFAULT_STEP_WEIGHT,
    length_scale: float = 1.0,
    jump_threshold: float | None = None,
) -> ReplanResult:
    """Straight-line Cartesian re-planning through the locked-arm closed-form IK (002 §§
    "Fault-tolerant trajectory planning", eqs. 19-20, Figs. 10-21).

    Every waypoint ``nominal Rx(gamma)`` is solved with the locked arm's closed form (002
    step 6); what the locked arm misses is the tracking error.  ``gamma`` (within the
    tolerance) and the locked-arm branch are chosen by ``method``:

    ``"continuous"`` (default)
        One shortest path over (waypoint x gamma grid x branch), all waypoints and
        candidates batched: the cost is ``sum_k e_k + step_weight * sum_k |q_{k+1} - q_k|^2``
        with ``e = position error + length_scale * rotation error`` [m] and the step in
        radians (wrapped), the goal held on the followed full-arm branch.  Where the path
        passes a gamma cell holding an exact root, gamma is refined to it (golden section
        within one cell either side, so the joints move by at most that), so the lock is
        absorbed exactly wherever the path can.  Where the lock cannot be absorbed the path
        moves gamma gradually rather than jumping between ``-tol`` and ``+tol``.
    ``"pointwise"``
        The first implementation, each waypoint on its own: the smallest ``|gamma|`` root of
        ``theta_j(gamma) = lock`` on the followed full-arm branch, else the ``gamma``
        minimising ``|theta_j(gamma) - lock|``, then the locked branch nearest the full-arm
        solution.  Neighbouring waypoints can switch between ``-tol`` and ``+tol`` or between
        branches, and the joints then jump (kept for comparison).

    Either way the result lists the largest joint step, every jump above ``jump_threshold``
    and every step that needs more than a joint's speed limit at this ``cycle``.

    Parameters
    ----------
    model
        A ``puma6``-family arm with exactly one locked joint.
    start, goal
        (4, 4) end poses [m].
    steps
        ``N`` interior points (eq. 19).
    cycle
        Time between waypoints [s].
    gamma_tolerance
        Largest ``|gamma|`` accepted [rad] (0: the line's orientation is kept).
    q_ref, branch
        Full-arm branch to follow at the goal (default: the branch nearest the locked arm's
        closed-form solution of the goal, i.e. chosen by ``q_ref`` if given).
    gamma_step
        Grid step for bracketing roots (``"pointwise"``) [rad]; the continuous path search
        uses ``max(gamma_step, PATH_GAMMA_STEP)`` with at most ``PATH_MAX_GAMMAS`` values.
    method
        ``"continuous"`` or ``"pointwise"``.
    step_weight
        [m / rad^2]: tracking error traded for one rad^2 of squared joint step.
    length_scale
        [m / rad]: weight of the rotation error in the tracking error.
    jump_threshold
        [rad]; default ``max(JUMP_MEDIAN_FACTOR * median step, JUMP_MIN_STEP)`` capped at
        ``JUMP_MAX_STEP`` (30 deg), the median
        taken over the steps' largest joint change.
    """
    geom_locked = puma6_geometry(model)
    if geom_locked.lock is None:
        raise ModelError(f"replan_line needs a model with one locked joint; {model.name!r} has none")
    _check_settings(cycle, gamma_tolerance, method, step_weight, length_scale, jump_threshold)
    joint, angle = geom_locked.lock
    geom = Puma6Geometry(geom_locked.a2, geom_locked.d4, geom_locked.d6, geom_locked.tool, None)
    nominal = line_waypoints(start, goal, steps)
    k = nominal.shape[0]
    goal_t = nominal[-1]
    if branch is None and q_ref is None:
        sol = ik_closed_form(model, goal_t)
        i = int(np.nanargmin(np.where(sol.valid, sol.position_error + sol.rotation_error, np.inf)))
        q_ref = sol.q_full[i]
    b = _pick_branch(geom, goal_t, None if q_ref is None else np.asarray(q_ref, dtype=float), branch)

    if method == "pointwise":
        gamma, q = _pointwise_plan(model, geom, nominal, b, joint, angle, gamma_tolerance, gamma_step)
    else:
        gamma, q = _continuous_plan(
            model,
            geom_locked,
            geom,
            nominal,
            b,
            gamma_tolerance,
            max(gamma_step, PATH_GAMMA_STEP),
            step_weight,
            length_scale,
        )

    target = tool_x_rotation(nominal, gamma)
    q = np.unwrap(q, axis=0)
    q_full = model.expand(q)
    actual = ee_pose(model, q)
    perr, rerr = pose_error(target, actual)
    pdev, rdev = pose_error(nominal, actual)
    absorbed = (perr <= EXACT_POSITION_TOL) & (rerr <= EXACT_ROTATION_TOL)
    if method == "pointwise":  # the first implementation's flag: a root on the followed branch
        absorbed |= _pointwise_absorbed(geom, nominal, gamma, b, joint, angle, gamma_tolerance, gamma_step)
    times = cast(FloatArray, np.arange(k) * cycle)
    dq = np.gradient(q, cycle, axis=0) if k > 1 else np.zeros_like(q)
    vel = _ee_twist(actual, cycle)

    step = np.abs(np.diff(q, axis=0))  # (K-1, n), q is unwrapped
    vlim = np.array([jt.velocity_limit for jt in model.joints], dtype=float)
    if jump_threshold is None:
        typical = float(np.median(step.max(axis=1))) if step.size else 0.0
        jump_threshold = min(max(JUMP_MEDIAN_FACTOR * typical, JUMP_MIN_STEP), JUMP_MAX_STEP)
    numbers = model.joint_numbers
    jumps = _flags(step, times, cycle, numbers, np.full(step.shape[1], float(jump_threshold)), per_rate=False)
    over = _flags(step, times, cycle, numbers, vlim, per_rate=True)
    return ReplanResult(
        times,
        q,
        q_full,
        dq,
        gamma,
        absorbed,
        nominal,
        target,
        actual,
        perr,
        rerr,
        pdev,
        rdev,
        vel,
        joint,
        float(angle),
        float(gamma_tolerance),
        b,
        float(cycle),
        step,
        vlim,
        float(jump_threshold),
        jumps,
        over,
        method,
    )


def _check_settings(cycle, gamma_tolerance, method, step_weight, length_scale, jump_threshold) -> None:
    """Refuse settings of :func:`replan_line` outside their ranges (ConfigurationError)."""
    if not (cycle > 0):
        raise ConfigurationError(f"cycle must be > 0 [s]; got {cycle}")
    if not (gamma_tolerance >= 0):
        raise ConfigurationError(f"gamma_tolerance must be >= 0 [rad]; got {gamma_tolerance}")
    if method not in ("continuous", "pointwise"):
        raise ConfigurationError(f"method must be 'continuous' or 'pointwise'; got {method!r}")
    if not (step_weight >= 0) or not (length_scale >= 0):
        raise ConfigurationError(
            f"step_weight and length_scale must be >= 0; got {step_weight}, {length_scale}"
        )
    if jump_threshold is not None and not (jump_threshold > 0):
        raise ConfigurationError(f"jump_threshold must be > 0 [rad]; got {jump_threshold}")


def _ee_twist(actual: FloatArray, cycle: float) -> FloatArray:
    """(K, 6) end-effector twist ``(v, omega)`` [m/s, rad/s] of the poses ``actual`` (K, 4, 4)
    ``cycle`` [s] apart: central differences inside, one-sided at the ends (zeros for K = 1)."""
    k = actual.shape[0]
    if k > 1:
        v = np.gradient(actual[:, :3, 3], cycle, axis=0)
        rel = rotation_log(actual[1:, :3, :3] @ np.swapaxes(actual[:-1, :3, :3], -1, -2)) / cycle
        w = np.empty((k, 3))
        w[0], w[-1] = rel[0], rel[-1]
        w[1:-1] = 0.5 * (rel[:-1] + rel[1:])
        vel = np.concatenate([v, w], axis=1)
    else:
        vel = np.zeros((k, 6))
    return vel


def _flags(step, times, cycle, numbers, limit, *, per_rate: bool) -> tuple[StepFlag, ...]:
    value = step / cycle if per_rate else step
    rows, cols = np.nonzero(value > limit[None, :])
    return tuple(
        StepFlag(
            int(i),
            float(times[i]),
            int(numbers[j]),
            float(step[i, j]),
            float(step[i, j] / cycle),
            float(limit[j]),
        )
        for i, j in zip(rows, cols)
    )
