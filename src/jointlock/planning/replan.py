"""Fault-tolerant re-planning of a non-redundant arm with one locked joint (seed 002).

* :func:`gamma_sweep` -- 002 §"Fault-tolerant planning based on the inverse solution of
  6-DOF manipulator", steps 1-4: rotate the target about the **tool x axis** by ``gamma``
  (eq. 18, ``T' = T Rx(gamma)``; the printed (1, 1) element 0 is a typo for 1), solve the
  full-arm closed-form IK for every ``gamma`` at once and follow one branch (Figs. 5-8).
* :func:`absorbable_range` -- the range of lock angles of a joint that some ``gamma`` within
  a tolerance can absorb (002: joint 2 "48 deg to 123 deg" over +-180 deg, "59.2 to 60.8 deg"
  over +-2 deg).
* :func:`gammas_for_lock` -- step 5: every ``gamma`` at which the full-arm IK puts the
  locked joint exactly at its locked angle (bracketing on a grid, then vectorised
  bisection), with the joint solution at each.
* :func:`replan_line` -- step 6 and eqs. (19)-(20): a straight Cartesian line solved with
  the locked-arm closed form, ``gamma`` (within the tolerance) and the branch chosen along
  the whole path (shortest path over waypoint x gamma x branch, tracking error against the
  squared joint steps) so that the joints do not jump; joint trajectories, poses, tracking
  errors, the largest joint step, jumps and speed-limit excesses.

Everything is batched over ``gamma`` and over waypoints; SI units and radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .._search1d import bisect_root, golden_section_minimize
from ..errors import ConfigurationError, ModelError
from ..ik import (
    EXACT_POSITION_TOL,
    EXACT_ROTATION_TOL,
    Puma6Geometry,
    _as_poses,
    ik_closed_form,
    puma6_branches,
    puma6_geometry,
    wrap_angle,
)
from ..kinematics import ee_pose
from ..model import ArmModel, FloatArray
from ..spatial import invert, pose_error, rot_x, rotation_log

#: Bisection steps when refining a gamma root (bracket 0.1 deg -> 1e-17 rad).
ROOT_BISECTIONS = 56
#: Default gamma grid step for bracketing roots [rad].
DEFAULT_GAMMA_STEP = math.radians(0.1)


def tool_x_rotation(target: ArrayLike, gamma: ArrayLike) -> FloatArray:
    """002 eq. (18), corrected: ``T Rx(gamma)``.

    Parameters
    ----------
    target
        (..., 4, 4) poses [m].
    gamma
        (...) rotation about the tool x axis [rad]; broadcast against ``target``'s batch.

    Returns
    -------
    (..., 4, 4) poses.  The printed (1, 1) element of eq. (18) is 0; it must be 1 (a
    rotation), and only then does E4 -> E5 of 002 (roll + gamma) hold.
    """
    return np.asarray(target, dtype=float) @ rot_x(gamma)


def _full_geometry(model: ArmModel) -> Puma6Geometry:
    geom = puma6_geometry(model)
    return Puma6Geometry(geom.a2, geom.d4, geom.d6, geom.tool, None)


def _full_branches(geom: Puma6Geometry, poses: FloatArray) -> tuple[FloatArray, FloatArray]:
    return puma6_branches(geom, poses @ invert(geom.tool))


def _pick_branch(
    geom: Puma6Geometry, target: FloatArray, q_ref: FloatArray | None, branch: int | None
) -> int:
    if branch is not None:
        if not 0 <= branch < 8:
            raise ConfigurationError(f"branch must be 0..7; got {branch}")
        return int(branch)
    if q_ref is None:
        raise ConfigurationError("give q_ref (full-arm joint angles [rad]) or branch to choose the IK branch")
    q0, valid = _full_branches(geom, target)
    dist = np.where(valid, np.max(np.abs(wrap_angle(q0 - q_ref)), axis=-1), np.inf)
    if not np.any(np.isfinite(dist)):
        raise ConfigurationError("the target is out of reach of the full arm: no IK branch exists")
    return int(np.argmin(dist))


@dataclass(frozen=True)
class GammaSweep:
    """Full-arm IK along the gamma sweep.

    Attributes
    ----------
    gammas
        (G,) rotation about the tool x axis [rad].
    q
        (G, 6) joint angles on the followed branch [rad], unwrapped along ``gammas`` so that
        each curve is continuous (value at the gamma nearest 0 within [-pi, pi)).
    q_branches
        (G, 8, 6) every branch [rad] in [-pi, pi) (NaN where it does not exist).
    valid
        (G,) the followed branch exists.
    branch
        Index of the followed branch (:func:`jointlock.ik.puma6_branches` order).
    target
        (4, 4) pose at ``gamma = 0`` [m].
    """

    gammas: FloatArray
    q: FloatArray
    q_branches: FloatArray
    valid: FloatArray
    branch: int
    target: FloatArray


def gamma_sweep(
    model: ArmModel,
    target: ArrayLike,
    gammas: ArrayLike | None = None,
    *,
    q_ref: ArrayLike | None = None,
    branch: int | None = None,
) -> GammaSweep:
    """Full-arm closed-form IK of ``T Rx(gamma)`` for every ``gamma`` (002 steps 1-4, Figs. 5-8).

    Parameters
    ----------
    model
        A ``puma6``-family arm (a locked one is accepted; its full arm is used).
    target
        (4, 4) desired pose [m] (002: FK of the desired joint angles).
    gammas
        (G,) [rad]; default ``[-pi, pi]`` in 0.1 deg steps.
    q_ref
        (6,) full-arm angles [rad] selecting the branch nearest to them at ``gamma = 0``
        (002 follows the branch of its desired configuration).
    branch
        Or the branch index directly.
    """
    geom = _full_geometry(model)
    t = _as_poses(target)
    g = np.linspace(-math.pi, math.pi, 3601) if gammas is None else np.asarray(gammas, dtype=float).ravel()
    b = _pick_branch(geom, t, None if q_ref is None else np.asarray(q_ref, dtype=float), branch)
    q_all, valid_all = _full_branches(geom, tool_x_rotation(t, g))
    q = q_all[:, b, :]
    valid = valid_all[:, b]
    q = _continuous(q, valid, g)
    return GammaSweep(g, q, q_all, valid, b, t)


def _continuous(q: FloatArray, valid: FloatArray, gammas: FloatArray) -> FloatArray:
    out = np.full(q.shape, np.nan)
    if not np.any(valid):
        return out
    idx = np.flatnonzero(valid)
    seg = np.unwrap(q[idx], axis=0)
    anchor = int(np.argmin(np.abs(gammas[idx])))
    seg = seg - 2 * math.pi * np.round((seg[anchor] - wrap_angle(seg[anchor])) / (2 * math.pi))
    out[idx] = seg
    return out


@dataclass(frozen=True)
class LockRange:
    """Lock angles of ``joint`` absorbable by some ``|gamma| <= gamma_limit``.

    Attributes
    ----------
    joint
        Joint number (1-based).
    gamma_limit
        [rad].
    lower, upper
        [rad]: min and max of the joint's angle over the sweep on the followed branch
        (continuous curve, so every angle in between is hit).
    gamma_at_lower, gamma_at_upper
        [rad] where they are reached.
    """

    joint: int
    gamma_limit: float
    lower: float
    upper: float
    gamma_at_lower: float
    gamma_at_upper: float


def absorbable_range(sweep: GammaSweep, joint: int, gamma_limit: float = math.pi) -> LockRange:
    """Range of lock angles of ``joint`` that the sweep absorbs within ``|gamma| <= gamma_limit``.

    002: joint 2 of ``q = [5, 60, 35, 10, -120, 90] deg`` -> "48 deg to 123 deg" (+-180 deg)
    and "59.2 deg to 60.8 deg" (+-2 deg).
    """
    if not 1 <= joint <= 6:
        raise ConfigurationError(f"joint must be 1..6; got {joint}")
    sel = (np.abs(sweep.gammas) <= gamma_limit + 1e-12) & sweep.valid
    if not np.any(sel):
        raise ConfigurationError(f"no valid sweep point with |gamma| <= {math.degrees(gamma_limit):g} deg")
    vals = sweep.q[sel, joint - 1]
    g = sweep.gammas[sel]
    i_lo, i_hi = int(np.argmin(vals)), int(np.argmax(vals))
    return LockRange(
        joint, float(gamma_limit), float(vals[i_lo]), float(vals[i_hi]), float(g[i_lo]), float(g[i_hi])
    )


@dataclass(frozen=True)
class GammaRoot:
    """A gamma at which the full-arm IK puts the locked joint at its locked angle.

    Attributes
    ----------
    gamma
        [rad].
    q_full
        (6,) joint angles [rad]; entry ``joint - 1`` equals ``angle`` to bisection accuracy.
    joint, angle
        The locked joint (1-based) and its angle [rad].
    branch
        Full-arm IK branch followed.
    """

    gamma: float
    q_full: FloatArray
    joint: int
    angle: float
    branch: int


def _locked_value(
    geom: Puma6Geometry, poses: FloatArray, gammas: FloatArray, branch: int, joint: int
) -> FloatArray:
    q, valid = _full_branches(geom, tool_x_rotation(poses, gammas))
    return np.where(valid[..., branch], q[..., branch, joint - 1], np.nan)


def _bisect(geom, poses, lo, hi, f_lo, branch, joint, angle):
    """Vectorised bisection of ``wrap(theta_j(gamma) - angle)`` on brackets (K,)."""
    return bisect_root(
        lambda g: wrap_angle(_locked_value(geom, poses, g, branch, joint) - angle),
        lo,
        hi,
        f_lo=f_lo,
        iterations=ROOT_BISECTIONS,
    )


def _brackets(f: FloatArray) -> FloatArray:
    """(..., G-1) sign changes of ``f`` (..., G) that are not 2 pi wrap jumps."""
    a, b = f[..., :-1], f[..., 1:]
    ok = np.isfinite(a) & np.isfinite(b) & (np.abs(a) < math.pi / 2) & (np.abs(b) < math.pi / 2)
    return ok & ((a == 0) | (np.sign(a) != np.sign(b)))


def gammas_for_lock(
    model: ArmModel,
    target: ArrayLike,
    joint: int,
    angle: float,
    *,
    q_ref: ArrayLike | None = None,
    branch: int | None = None,
    gamma_limit: float = math.pi,
    step: float = DEFAULT_GAMMA_STEP,
) -> tuple[GammaRoot, ...]:
    """Every ``gamma`` in ``[-gamma_limit, gamma_limit]`` at which the full-arm IK of
    ``T Rx(gamma)`` (on the chosen branch) puts ``joint`` exactly at ``angle`` (002 step 5).

    Parameters
    ----------
    model
        ``puma6``-family arm.
    target
        (4, 4) desired pose [m].
    joint, angle
        Locked joint (1-based) and its angle [rad].
    q_ref, branch
        Branch selection, as in :func:`gamma_sweep`.
    gamma_limit
        Fault tolerance [rad].
    step
        Grid step used to bracket the roots [rad]; each bracket is then bisected to
        machine precision.

    Returns
    -------
    tuple of GammaRoot, smallest ``|gamma|`` first (empty when the lock cannot be absorbed).
    """
    if not 1 <= joint <= 6:
        raise ConfigurationError(f"joint must be 1..6; got {joint}")
    geom = _full_geometry(model)
    t = _as_poses(target)
    b = _pick_branch(geom, t, None if q_ref is None else np.asarray(q_ref, dtype=float), branch)
    count = max(2, int(math.ceil(2 * gamma_limit / step)) + 1)
    grid = np.linspace(-gamma_limit, gamma_limit, count)
    f = wrap_angle(_locked_value(geom, t, grid, b, joint) - angle)
    br = np.flatnonzero(_brackets(f))
    if br.size == 0:
        return ()
    gam = _bisect(geom, t, grid[br], grid[br + 1], f[br], b, joint, angle)
    gam = np.where(f[br] == 0, grid[br], gam)
    q, _ = _full_branches(geom, tool_x_rotation(t, gam))
    roots = [GammaRoot(float(g), q[k, b].copy(), joint, float(angle), b) for k, g in enumerate(gam)]
    roots.sort(key=lambda r: abs(r.gamma))
    unique: list[GammaRoot] = []
    for r in roots:
        if all(abs(r.gamma - u.gamma) > 1e-9 for u in unique):
            unique.append(r)
    return tuple(unique)


# -- straight-line re-planning ---------------------------------------------------------------


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
    from ..spatial import axis_angle_rotation

    angle = np.linalg.norm(rel)
    axis = rel / angle if angle > 0 else np.array([1.0, 0.0, 0.0])
    rots = a[:3, :3] @ axis_angle_rotation(axis, s * angle)
    out = np.zeros((s.size, 4, 4))
    out[:, :3, :3] = rots
    out[:, :3, 3] = a[:3, 3] + s[:, None] * (c[:3, 3] - a[:3, 3])
    out[:, 3, 3] = 1.0
    return out


#: Gamma grid step of the continuous plan's path search [rad]; absorbed waypoints are then
#: refined to the exact root within one cell either side.
PATH_GAMMA_STEP = math.radians(0.25)
#: Most gamma values per waypoint in the path search (the grid coarsens beyond).
PATH_MAX_GAMMAS = 161
#: Golden-section steps of that refinement (a cell shrinks by 0.618**64 ~ 4e-14).
REFINE_STEPS = 64
#: Default weight of the squared joint step against the tracking error [m / rad^2].
DEFAULT_STEP_WEIGHT = 0.5
#: The goal's tracking error counts this many times (the task is to reach it).
GOAL_WEIGHT = 100.0
#: Default jump threshold: this many times the median largest joint step ...
JUMP_MEDIAN_FACTOR = 5.0
#: ... and at least this [rad] ...
JUMP_MIN_STEP = math.radians(2.0)
#: ... and at most this [rad]: a joint that moves more between two waypoints is flagged even
#: when every step is that large (a plan too coarse to follow the line: few waypoints).
JUMP_MAX_STEP = math.radians(30.0)



@dataclass(frozen=True)
class StepFlag:
    """One joint's motion between waypoints ``index`` and ``index + 1`` that is flagged.

    Attributes
    ----------
    index
        The step goes from waypoint ``index`` to ``index + 1``.
    time
        [s] at waypoint ``index``.
    joint
        Full-arm number (1-based) of the joint.
    step
        Its change over the step [rad] (absolute, wrapped).
    rate
        ``step / cycle`` [rad/s].
    limit
        The threshold it exceeds: [rad] for a jump, [rad/s] for a velocity limit.
    """

    index: int
    time: float
    joint: int
    step: float
    rate: float
    limit: float


@dataclass(frozen=True)
class ReplanResult:
    """A straight Cartesian plan executed by the locked arm.

    Attributes
    ----------
    times
        (K,) [s], ``cycle`` apart (002: 250 ms).
    q
        (K, n) movable-joint angles [rad], unwrapped in time.
    q_full
        (K, 6) with the locked joint [rad].
    dq
        (K, n) joint rates [rad/s] (central differences).
    gamma
        (K,) rotation about the tool x axis chosen at each waypoint [rad], within the tolerance.
    absorbed
        (K,) the lock is absorbed exactly: the locked arm reaches ``nominal Rx(gamma)``
        (tracking error within :data:`jointlock.ik.EXACT_POSITION_TOL` /
        :data:`~jointlock.ik.EXACT_ROTATION_TOL`).
    nominal
        (K, 4, 4) the straight-line poses [m].
    target
        (K, 4, 4) ``nominal Rx(gamma)``: what the locked arm is asked to reach.
    actual
        (K, 4, 4) forward kinematics of ``q``.
    position_error, rotation_error
        (K,) actual vs target [m], [rad] (the tracking error).
    position_deviation, rotation_deviation
        (K,) actual vs nominal [m], [rad] (includes the accepted gamma).
    ee_velocity
        (K, 6) end-effector twist ``(v, omega)`` [m/s, rad/s], finite differences, root frame.
    joint, lock_angle, gamma_tolerance, branch, cycle
        The settings (``branch``: the full-arm branch followed at the goal).
    joint_step
        (K-1, n) ``|q[k+1] - q[k]|`` per movable joint [rad].
    velocity_limit
        (n,) the model's joint speed limits [rad/s] (``inf`` when unknown).
    jump_threshold
        A step of any joint above this is a jump [rad].
    jumps
        Every (step, joint) above ``jump_threshold``, in time order.
    over_velocity
        Every (step, joint) whose ``joint_step / cycle`` exceeds the joint's speed limit.
    method
        ``"continuous"`` (gamma and branch chosen along the path) or ``"pointwise"``
        (each waypoint on its own, the first implementation).
    """

    times: FloatArray
    q: FloatArray
    q_full: FloatArray
    dq: FloatArray
    gamma: FloatArray
    absorbed: FloatArray
    nominal: FloatArray
    target: FloatArray
    actual: FloatArray
    position_error: FloatArray
    rotation_error: FloatArray
    position_deviation: FloatArray
    rotation_deviation: FloatArray
    ee_velocity: FloatArray
    joint: int
    lock_angle: float
    gamma_tolerance: float
    branch: int
    cycle: float
    joint_step: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    velocity_limit: FloatArray = field(default_factory=lambda: np.zeros(0))
    jump_threshold: float = math.inf
    jumps: tuple[StepFlag, ...] = ()
    over_velocity: tuple[StepFlag, ...] = ()
    method: str = "pointwise"

    @property
    def max_joint_step(self) -> float:
        """Largest change of any joint between neighbouring waypoints [rad]."""
        return float(self.joint_step.max()) if self.joint_step.size else 0.0

    @property
    def max_joint_step_at(self) -> tuple[int, int]:
        """``(index, joint)``: the step ``index -> index + 1`` and the full-arm joint number
        of :attr:`max_joint_step`."""
        if not self.joint_step.size:
            return (0, 0)
        i, j = np.unravel_index(int(np.argmax(self.joint_step)), self.joint_step.shape)
        numbers = [n for n in range(1, self.q_full.shape[1] + 1) if n != self.joint]
        return int(i), int(numbers[j])

    @property
    def step_rate(self) -> FloatArray:
        """(K-1, n) ``joint_step / cycle`` [rad/s]: the speed each step needs."""
        return self.joint_step / self.cycle


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
    times = np.arange(k) * cycle
    dq = np.gradient(q, cycle, axis=0) if k > 1 else np.zeros_like(q)
    if k > 1:
        v = np.gradient(actual[:, :3, 3], cycle, axis=0)
        rel = rotation_log(actual[1:, :3, :3] @ np.swapaxes(actual[:-1, :3, :3], -1, -2)) / cycle
        w = np.empty((k, 3))
        w[0], w[-1] = rel[0], rel[-1]
        w[1:-1] = 0.5 * (rel[:-1] + rel[1:])
        vel = np.concatenate([v, w], axis=1)
    else:
        vel = np.zeros((k, 6))

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


def _pointwise_grid(gamma_tolerance: float, gamma_step: float) -> FloatArray:
    count = max(1, 2 * int(math.ceil(gamma_tolerance / gamma_step)) + 1) if gamma_tolerance > 0 else 1
    return np.linspace(-gamma_tolerance, gamma_tolerance, count)


def _pointwise_plan(model, geom, nominal, b, joint, angle, gamma_tolerance, gamma_step):
    """The first implementation: gamma and branch chosen at each waypoint on its own."""
    k = nominal.shape[0]
    grid = _pointwise_grid(gamma_tolerance, gamma_step)
    f = wrap_angle(_locked_value(geom, nominal[:, None], grid[None, :], b, joint) - angle)  # (K, G)
    gamma = grid[np.argmin(np.where(np.isfinite(f), np.abs(f), np.inf), axis=1)]
    if grid.size > 1:
        brk = _brackets(f)  # (K, G-1)
        mid = 0.5 * (grid[:-1] + grid[1:])
        score = np.where(brk, np.abs(mid), np.inf)
        j = np.argmin(score, axis=1)
        has = np.isfinite(score[np.arange(k), j])
        if np.any(has):
            rows = np.flatnonzero(has)
            gamma[rows] = _bisect(
                geom, nominal[rows], grid[j[rows]], grid[j[rows] + 1], f[rows, j[rows]], b, joint, angle
            )
    target = tool_x_rotation(nominal, gamma)
    full_q, full_valid = _full_branches(geom, target)
    ref = full_q[:, b, :]
    locked = ik_closed_form(model, target)  # (K, 4)
    dist = np.max(np.abs(wrap_angle(locked.q_full - ref[:, None, :])), axis=-1)
    cost = np.where(locked.valid, locked.position_error + locked.rotation_error, np.inf)
    # prefer the branch on the followed full-arm solution; else the most accurate one
    choice = np.where(
        full_valid[:, b], np.argmin(np.where(locked.valid, dist, np.inf), axis=1), np.argmin(cost, 1)
    )
    return gamma, locked.q[np.arange(k), choice]


def _pointwise_absorbed(geom, nominal, gamma, b, joint, angle, gamma_tolerance, gamma_step):
    k = nominal.shape[0]
    grid = _pointwise_grid(gamma_tolerance, gamma_step)
    out = np.zeros(k, dtype=bool)
    if grid.size > 1:
        f = wrap_angle(_locked_value(geom, nominal[:, None], grid[None, :], b, joint) - angle)
        out = np.any(_brackets(f), axis=1)
    return out | (np.abs(wrap_angle(_locked_value(geom, nominal, gamma, b, joint) - angle)) < 1e-9)


def _continuous_plan(
    model, geom_locked, geom, nominal, b, gamma_tolerance, grid_step, step_weight, length_scale
):
    """Shortest path over (waypoint x gamma x locked branch); see :func:`replan_line`."""
    k = nominal.shape[0]
    if gamma_tolerance > 0:
        count = min(2 * int(math.ceil(gamma_tolerance / grid_step)) + 1, PATH_MAX_GAMMAS)
        grid = np.linspace(-gamma_tolerance, gamma_tolerance, max(count, 3))
    else:
        grid = np.zeros(1)
    g = grid.size
    sol = ik_closed_form(model, tool_x_rotation(nominal[:, None], grid[None, :]))  # (K, G, B)
    nb = sol.valid.shape[-1]
    err = np.where(sol.valid, sol.position_error + length_scale * sol.rotation_error, np.inf)
    # the goal stays on the followed full-arm branch: its nearest locked branch at each gamma
    full_q, full_valid = _full_branches(geom, tool_x_rotation(nominal[-1], grid))  # (G, 8, 6)
    ref = full_q[:, b, :]
    dist = np.max(np.abs(wrap_angle(sol.q_full[-1] - ref[:, None, :])), axis=-1)  # (G, B)
    near = np.argmin(np.where(sol.valid[-1], dist, np.inf), axis=1)
    keep = (np.arange(nb)[None, :] == near[:, None]) | ~full_valid[:, b, None]
    if np.any(keep & sol.valid[-1]):
        err[-1] = np.where(keep, err[-1], np.inf)
    err[-1] *= GOAL_WEIGHT
    node = _shortest_path(sol.q.reshape(k, g * nb, -1), err.reshape(k, g * nb), step_weight)
    gi, bi = np.divmod(node, nb)
    rows = np.arange(k)
    gamma = grid[gi]
    q = sol.q[rows, gi, bi]
    if g > 1:  # refine to an exact root within one cell either side, where there is one
        lo = grid[np.maximum(gi - 1, 0)]
        hi = grid[np.minimum(gi + 1, g - 1)]
        gam_r = _golden(lambda x: _branch_error(model, geom_locked, nominal, x, bi, length_scale)[0], lo, hi)
        pe, re, q_r = _branch_error(model, geom_locked, nominal, gam_r, bi, 0.0)
        exact = (pe <= EXACT_POSITION_TOL) & (re <= EXACT_ROTATION_TOL)
        gamma = np.where(exact, gam_r, gamma)
        q = np.where(exact[:, None], q_r, q)
    return gamma, q


def _branch_error(model, geom_locked, nominal, gammas, branches, length_scale):
    """Tracking error (position + length_scale * rotation), rotation error and joints of one
    locked branch per waypoint, each at its own gamma (closed form without the geometry fit)."""
    rows = np.arange(nominal.shape[0])
    target = tool_x_rotation(nominal, gammas)
    q_full, valid = puma6_branches(geom_locked, target @ invert(geom_locked.tool))
    q = model.healthy(q_full[rows, branches])
    ok = valid[rows, branches]
    pe, re = pose_error(target, ee_pose(model, np.where(ok[:, None], q, 0.0)))
    pe, re = np.where(ok, pe, np.inf), np.where(ok, re, np.inf)
    return pe + length_scale * re, re, q


def _golden(fun, lo: FloatArray, hi: FloatArray) -> FloatArray:
    """Vectorised golden-section minimisation of ``fun`` (K,) -> (K,) on ``[lo, hi]``."""
    return golden_section_minimize(fun, lo, hi, iterations=REFINE_STEPS).x


def _shortest_path(q: FloatArray, cost: FloatArray, weight: float) -> np.ndarray:
    """Viterbi over waypoints: nodes ``q`` (K, N, n) [rad] (NaN where invalid) with node
    costs ``cost`` (K, N) (``inf`` where invalid); edge cost ``weight * |wrap(dq)|^2``.
    Returns the (K,) node of the cheapest path."""
    k, n_nodes, n = q.shape
    ok = np.isfinite(cost)
    bad = np.flatnonzero(~np.any(ok, axis=1))
    if bad.size:
        raise ConfigurationError(f"waypoint {int(bad[0])} has no locked-arm IK solution")
    qz = np.where(ok[..., None], q, 0.0)
    acc = cost[0].copy()
    back = np.zeros((k, n_nodes), dtype=np.intp)
    cols = np.arange(n_nodes)
    two_pi = 2.0 * math.pi
    for i in range(1, k):
        d = np.abs(qz[i][None, :, :] - qz[i - 1][:, None, :])  # (prev, next, n), in [0, 2 pi)
        d = np.minimum(d, two_pi - d)  # wrapped |dq|
        trans = acc[:, None] + weight * np.einsum("ijk,ijk->ij", d, d)
        back[i] = np.argmin(trans, axis=0)
        acc = trans[back[i], cols] + cost[i]
    path = np.empty(k, dtype=np.intp)
    path[-1] = int(np.argmin(acc))
    for i in range(k - 1, 0, -1):
        path[i - 1] = back[i, path[i]]
    return path
