"""Clearance of a halt (issue 27): which values of the shared ``k`` give a halt motion that keeps
the clearance required between the arm's links, its spacecraft bus and keep-out volumes
(:func:`jointlock.collision.clearance`) on every sample of the constraint grid.

A pair that is already closer than required at the state at failure (the same for every ``k``:
the halt polynomial starts there) may not come closer still: its floor is its distance at
``t = 0``.  Like the torques, the clearance is not affine in ``k``, so its feasible set may be
several stretches: a scan of ``n_scan`` values, each feasible/infeasible boundary bisected to
:data:`BOUNDARY_RTOL` of the width (:func:`jointlock._search1d.bisect_boundary`).

Between the samples of the grid a halt is held to the same floor by a certified bound
(:func:`jointlock.sweep.swept_clearance`): it may come closer than its samples show by at most
:data:`~jointlock.sweep.TUNNEL_TOLERANCE_M`, so that no link passes through another, or through
the bus, unseen.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..._search1d import bisect_boundary, true_segments
from ...collision import clearance, smallest_excess
from ...errors import ConfigurationError
from ...model import FloatArray
from ...shapes import Shape
from ...sweep import SweptClearance, swept_clearance
from ._actuator_limits import torque_violations
from ._constants import CHUNK_SAMPLES
from ._feasibility import shared_k_interval
from ._powell import powell_per_joint
from ._problem import HaltProblem

#: Relative width of the refined boundaries of the clear set of ``k`` [-].
BOUNDARY_RTOL = 1e-9
#: Scan points of ``k`` for the clearance (each a whole motion on the constraint grid).
CLEARANCE_SCAN = 41
#: :func:`keeps_clearance` looks at every this many check times first,
SCREEN_STRIDE = 16
#: and at this many first check times: a halt from a state whose pair is at its floor and
#: closing in breaks it on the first samples, whatever ``k`` and ``T``.
SCREEN_HEAD = 4
#: The screen's levels, coarse to fine: the first :data:`SCREEN_HEAD` check times (0), then
#: every 128th, then every :data:`SCREEN_STRIDE`-th.
SCREEN_LEVELS = (0, 128, SCREEN_STRIDE)


def clearance_shortfall(
    problem: HaltProblem, k: FloatArray, margin: float, keep_out: Sequence[Shape] = (), *, per_joint: bool = False
) -> FloatArray:
    """(...) the largest amount [m] by which a halt at ``k`` (...) [rad/s^6] comes closer than
    allowed (for each pair the smaller of its allowance, ``margin`` or 0 for a mounted pair, and
    its distance at ``t = 0``): on the constraint grid, or between its samples by more than the
    tunnelling tolerance (:func:`halt_swept_clearance`); <= 0: clear.  ``per_joint``: ``k`` is
    one halt's (n,) per-joint ``k`` (the vector solver's); the result a 0-d array."""
    k = np.asarray(k, dtype=float)
    floor = _floor(problem, margin, keep_out)
    if per_joint:
        if k.shape != (problem.dof,):
            raise ConfigurationError(
                f"per_joint: k must be one halt's per-joint k, shape ({problem.dof},) [rad/s^6]; got shape {k.shape}"
            )
        return np.asarray(halt_swept_clearance(problem, k, floor, keep_out, per_joint=True).shortfall)
    out = [halt_swept_clearance(problem, float(x), floor, keep_out).shortfall for x in k.reshape(-1)]
    return np.array(out).reshape(k.shape)


def halt_swept_clearance(
    problem: HaltProblem,
    k: float | FloatArray,
    floor: FloatArray,
    keep_out: Sequence[Shape] = (),
    *,
    per_joint: bool = False,
    sampled: tuple[FloatArray, FloatArray, FloatArray, FloatArray] | None = None,
) -> SweptClearance:
    """The clearance of the halt at a shared ``k`` [rad/s^6] (``per_joint``: (n,), one per
    joint) on the constraint grid and between its samples (:func:`jointlock.sweep.
    swept_clearance`), each pair held to ``floor`` (P,) [m]; ``sampled``: the grid's q, dq, ddq
    and distances, already computed."""

    def motion(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return problem.trajectory(k, t, per_joint=per_joint)

    t = problem.times(problem.n_check)
    return swept_clearance(problem.model, motion, t, floor, keep_out=keep_out, sampled=sampled)


def _floor(problem: HaltProblem, margin: float, keep_out: Sequence[Shape]) -> FloatArray:
    """(P,) the distance each pair must keep [m] (see :func:`clearance_shortfall`)."""
    at_failure = clearance(problem.model, problem.q0, keep_out=keep_out)
    return np.minimum(np.where(at_failure.mounted_pairs, 0.0, margin), at_failure.pair_distance)


def _shortfall_at(
    problem: HaltProblem, k: FloatArray, index: np.ndarray, floor: FloatArray, keep_out: Sequence[Shape]
) -> FloatArray:
    """(K,) the largest shortfall [m] of the halts at ``k`` (K,) over the check times
    ``times(n_check)[index]`` (``index``: a mask of the check grid; -inf when there are none)."""
    n_t = int(np.count_nonzero(index))
    if n_t == 0:
        return np.full(k.size, -np.inf)
    out = np.empty(k.size)
    step = max(1, CHUNK_SAMPLES // n_t)
    for start in range(0, k.size, step):
        q, _, _ = problem.on_grid(k[start : start + step], problem.n_check, index)
        # max(floor - d) over times and pairs as 0 - min(d - floor), without the distances of
        # pairs far from their floor: the same value (IEEE subtraction is antisymmetric; 0 - x
        # keeps a zero +0, as floor - d gives it)
        excess, _ = smallest_excess(problem.model, q, floor, keep_out=keep_out)  # (K, n_t)
        out[start : start + step] = 0.0 - excess.min(axis=-1)
    return out


def keeps_clearance(
    problem: HaltProblem, k: FloatArray, margin: float, keep_out: Sequence[Shape] = (), *, any_one: bool = False
) -> np.ndarray:
    """(K,) bool: whether the halt at each ``k`` (K,) [rad/s^6] keeps the clearance on the whole
    constraint grid and between its samples (``clearance_shortfall(...) <= 0``, the same answer).

    The first :data:`SCREEN_HEAD` check times, then every 128th, then every
    :data:`SCREEN_STRIDE`-th are looked at first (:data:`SCREEN_LEVELS`): a halt that comes too
    close there does not keep it (most of a scan's colliding halts are caught so, at a fraction
    of the cost); only the others are checked on the rest of the grid, and those clear there
    between its samples.  A configuration's distances do not depend on the batch it is computed
    in, so the answer is that of the whole grid.

    ``any_one``: only whether one of them keeps it is asked.  The others are checked one at a
    time, the clearest on the screen first, up to the first that keeps it (True); the rest are
    left False."""
    k = np.asarray(k, dtype=float).reshape(-1)
    n_t = problem.n_check
    floor = _floor(problem, margin, keep_out)
    # coarse to fine: a pair closing in on its floor at the failure is caught on the first
    # samples, a halt sweeping through the bus on a few samples; each level looks only at the
    # halts still clear and at times not looked at yet
    screen = np.full(k.size, -np.inf)
    seen = np.zeros(n_t, dtype=bool)
    seen[0] = True  # the floor is the distance at t = 0 where that is smaller
    for stride in SCREEN_LEVELS:
        level = np.zeros(n_t, dtype=bool)
        if stride:
            level[::stride] = True
            level[-1] = True
        else:
            level[:SCREEN_HEAD] = True
        level &= ~seen
        alive = screen <= 0.0
        if alive.any() and level.any():
            screen[alive] = np.maximum(screen[alive], _shortfall_at(problem, k[alive], level, floor, keep_out))
        seen |= level
    survivors = np.flatnonzero(screen <= 0.0)
    if any_one:  # the clearest on the screen first
        survivors = survivors[np.argsort(screen[survivors], kind="stable")]
    ok = np.zeros(k.size, dtype=bool)
    for i in survivors:
        ok[i] = _clear_everywhere(problem, float(k[i]), floor, keep_out)
        if any_one and ok[i]:
            break
    return ok


def _clear_everywhere(problem: HaltProblem, k: float, floor: FloatArray, keep_out: Sequence[Shape]) -> bool:
    """Whether the halt at ``k`` keeps ``floor`` on every check time and between them."""
    q, dq, ddq = problem.on_grid(k, problem.n_check)
    distance = clearance(problem.model, q, keep_out=keep_out, witness=False).pair_distance
    if distance.shape[-1] and float((floor - distance).max()) > 0.0:
        return False
    return bool(halt_swept_clearance(problem, k, floor, keep_out, sampled=(q, dq, ddq, distance)).shortfall <= 0.0)


def clear_k_segments(
    problem: HaltProblem,
    lo: float,
    hi: float,
    margin: float,
    keep_out: Sequence[Shape] = (),
    n_scan: int = CLEARANCE_SCAN,
) -> list[tuple[float, float]]:
    """The stretches of ``[lo, hi]`` [rad/s^6] whose halts keep the clearance (see the module);
    the refined ends on the clear side."""

    def clear(x: FloatArray) -> np.ndarray:
        return keeps_clearance(problem, x, margin, keep_out).reshape(np.shape(x))

    return true_segments(clear, lo, hi, n_scan, BOUNDARY_RTOL)


def clear_k_exists(
    problem: HaltProblem, margin: float, keep_out: Sequence[Shape] = (), n_scan: int = CLEARANCE_SCAN
) -> bool:
    """Whether a shared ``k`` among the ``n_scan`` points of the feasible interval that
    :func:`clear_k_segments` scans gives a halt keeping every limit (the motor and brake torques
    too) and the clearance: the stretches the halt job can choose from are not empty."""
    lo, hi = shared_k_interval(problem)
    if not lo <= hi:
        return False
    grid = np.linspace(lo, hi, max(n_scan, 2)) if hi > lo else np.array([lo])
    if problem.has_torque_limits:
        grid = np.array([k for k in grid if not torque_violations(problem, float(k))])
    return bool(grid.size) and bool(keeps_clearance(problem, grid, margin, keep_out, any_one=True).any())


#: Growth of the halt time per step of :func:`minimum_clear_halt_time` [-].
CLEAR_T_GROWTH = 1.1
#: Width to which :func:`minimum_clear_halt_time` refines its bracket [s].
CLEAR_T_TOL = 1e-2
#: :func:`minimum_clear_halt_time` looks up to this many times the longer of the halt time
#: asked and the limits' smallest one.
CLEAR_T_SPAN = 2.0


def clear_T_range(T: float, start: float) -> float:
    """The longest halt time [s] :func:`minimum_clear_halt_time` tries, for the halt time ``T``
    asked and the limits' smallest ``start`` [s]."""
    return CLEAR_T_SPAN * max(T, start)


def minimum_clear_halt_time(
    problem: HaltProblem, margin: float, keep_out: Sequence[Shape] = (), *, start: float | None
) -> float | None:
    """Smallest halt time [s] whose halt keeps every limit and the clearance (a shared ``k`` of
    :func:`clear_k_exists`): from ``start`` (the limits' smallest ``T``: none, None), ``T`` grows
    by :data:`CLEAR_T_GROWTH` per step up to :func:`clear_T_range`, then the first bracket
    without and with such a ``k`` is bisected to :data:`CLEAR_T_TOL`.  None when no halt time in
    that range has one.

    The clearance need not improve with ``T`` (a longer halt carries the arm further along its
    rate at failure first), so this is the first such ``T`` on that grid, not a proven minimum;
    and the range is shorter than the limits' (``max(10 T, 120 s)``): most halts that collide
    start closing in on the bus at the failure, whatever ``T``, and each step is a scan of ``k``
    with the clearance."""
    if start is None:
        return None
    t_max = clear_T_range(problem.T, start)

    def ok(T: float) -> bool:
        return clear_k_exists(problem.with_time(T), margin, keep_out)

    t, prev = float(start), None
    while t <= t_max:
        if ok(t):
            if prev is None:
                return t
            found = bisect_boundary(
                lambda x: np.array([ok(float(v)) for v in np.ravel(x)]).reshape(np.shape(x)), prev, t, xtol=CLEAR_T_TOL
            )
            return float(found.true_end)
        prev, t = t, t * CLEAR_T_GROWTH
    return None


def clear_per_joint_k(
    problem: HaltProblem, intervals: FloatArray, k_start: float, margin: float, keep_out: Sequence[Shape] = ()
) -> tuple[FloatArray, dict[str, object]]:
    """One ``k`` per joint whose halt keeps the clearance (issue 27): Powell within each joint's
    feasible interval ``intervals`` (n, 2) [rad/s^6] (the vector solver's), started from the
    shared ``k_start`` [rad/s^6], whose halt keeps it.  A halt that comes closer than allowed
    (:func:`clearance_shortfall`, between samples too) is held above every clear one: its value
    is the start's objective times ten plus its shortfall, so Powell's line searches turn back
    at the clear set's edge.  Returns the best clear (n,) ``k`` found (the start as (n,) when
    Powell finds none better) and scipy's record."""
    from ._objective import halt_objective

    start = np.clip(np.full(problem.dof, float(k_start)), intervals[:, 0], intervals[:, 1])
    scale = max(float(np.max(intervals[:, 1] - intervals[:, 0])), 1e-12)
    floor_value = float(halt_objective(problem, start, per_joint=True))
    barrier = 10.0 * abs(floor_value) + 1.0

    def value(k: FloatArray) -> float:
        k = np.clip(k, intervals[:, 0], intervals[:, 1])
        short = float(clearance_shortfall(problem, k, margin, keep_out, per_joint=True))
        if short > 0.0:
            return barrier + short
        return float(halt_objective(problem, k, per_joint=True))

    k, record = powell_per_joint(value, start, intervals, scale)
    best = k if value(k) < floor_value else start
    return best, {**record, "clearance": True}
