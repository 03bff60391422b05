"""The limits of one halt problem (000 eq. 33): exact feasible ``k`` interval, violations,
least-violating ``k`` and the smallest feasible halt time."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..._search1d import bisect_boundary
from ...compiled import use_compiled
from ...forward import COMPILED_MIN_BATCH
from ...model import FloatArray
from ._constants import LIMIT_RTOL, LimitKind
from ._polynomial import k_shape
from ._problem import HaltProblem


@dataclass(frozen=True)
class Violation:
    """One violated limit: joint number (1-based), which limit, the limit, the worst value
    reached, by how much it is exceeded (same unit, > 0), and when [s].  Values in SI
    (rad, rad/s, rad/s^2; N m for a motor ``"torque"`` or a locked joint's ``"brake"``)."""

    joint: int
    kind: LimitKind
    limit: float
    value: float
    excess: float
    time: float

    @property
    def display(self) -> tuple[float, float, float, str]:
        """``(value, limit, excess, unit)`` as people read them: degrees, or N m."""
        if self.kind in ("torque", "brake"):
            return self.value, self.limit, self.excess, "N m"
        unit = {"angle": "deg", "velocity": "deg/s", "acceleration": "deg/s^2"}[self.kind]
        return math.degrees(self.value), math.degrees(self.limit), math.degrees(self.excess), unit

    def describe(self) -> str:
        value, limit, excess, unit = self.display
        what = {"torque": "motor torque", "brake": "brake torque (locked)"}.get(self.kind, self.kind)
        return (
            f"joint {self.joint} {what} reaches {value:.3f} {unit} at "
            f"t = {self.time:.3f} s: limit {limit:.3f} {unit} exceeded by "
            f"{excess:.3f} {unit} ({100 * self.excess / abs(self.limit):.1f} %)"
        )


def _limits(problem: HaltProblem) -> tuple[FloatArray, FloatArray]:
    """(3, n) lower and upper limits for angle, velocity, acceleration."""
    assert problem.q_min is not None and problem.q_max is not None  # set by HaltProblem.__post_init__
    lo = np.stack([problem.q_min, -problem.dq_max, -problem.ddq_max])
    hi = np.stack([problem.q_max, problem.dq_max, problem.ddq_max])
    return lo, hi


def _slack(lo: FloatArray, hi: FloatArray) -> FloatArray:
    """Round-off slack of each limit (relative to its finite ends; an infinite end -- no
    limit -- needs none)."""
    lo, hi = np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0)
    return LIMIT_RTOL * np.maximum(np.maximum(np.abs(lo), np.abs(hi)), 1.0)


def feasible_k_intervals(problem: HaltProblem) -> FloatArray:
    """Exact feasible interval of ``k`` for every joint on the check grid.

    Each limit at each time is affine in ``k`` (``g0(t) + k phi(t)``), so every joint's
    feasible set is an interval; for a shared ``k`` (000) intersect them
    (:func:`shared_k_interval`).

    Returns
    -------
    (n, 2) ``[k_min, k_max]`` per joint [rad/s^6]; ``k_min > k_max`` (or NaN-free
    ``+inf/-inf``) when empty.
    """
    t, base_parts, shape_parts = problem.profiles(problem.n_check)
    base = np.stack(base_parts)  # (3, n_t, n)
    lo, hi = _limits(problem)
    sl = _slack(lo, hi)
    if use_compiled(t.size, COMPILED_MIN_BATCH):  # the same numbers, one pass (a campaign's workers)
        from ... import _kernels

        out = np.empty((problem.dof, 2))
        _kernels.k_intervals(base, np.stack(shape_parts), lo, hi, lo - sl, hi + sl, out)
        return out
    shape = np.stack(shape_parts)[:, :, None]  # (3, n_t, 1)
    lo_s, hi_s = (lo - sl)[:, None, :], (hi + sl)[:, None, :]
    nz = np.abs(shape) > 0
    safe = np.where(nz, shape, 1.0)
    b1 = (lo[:, None, :] - base) / safe  # exact limits, so that k on a bound is within the slack
    b2 = (hi[:, None, :] - base) / safe
    kmin = np.where(nz, np.minimum(b1, b2), -np.inf)
    kmax = np.where(nz, np.maximum(b1, b2), np.inf)
    # where phi^(j)(t) = 0 the value does not depend on k: it must already be within limits
    fixed_bad = (~nz) & ((base < lo_s) | (base > hi_s))
    kmin = np.where(fixed_bad, np.inf, kmin)
    kmax = np.where(fixed_bad, -np.inf, kmax)
    return np.stack([kmin.max(axis=(0, 1)), kmax.min(axis=(0, 1))], axis=-1)


def shared_k_interval(problem: HaltProblem) -> tuple[float, float]:
    """Feasible interval of one shared ``k`` [rad/s^6]; empty when ``lo > hi``."""
    per = feasible_k_intervals(problem)
    return float(per[:, 0].max()), float(per[:, 1].min())


def relative_violation(problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False) -> FloatArray:
    """Largest limit excess relative to its limit (0 when feasible), for a batch of ``k``:
    (...) [-]; a number per candidate, max over joints, limits and the check grid."""
    lo, hi = _limits(problem)
    traj = np.stack(problem.on_grid(k, problem.n_check, per_joint=per_joint), axis=-3)  # (..., 3, n_t, n)
    scale = np.maximum(np.abs(lo), np.abs(hi))
    scale = np.where(np.isfinite(scale), scale, 1.0)[:, None, :]  # no angle limit: never exceeded
    excess = np.maximum(traj - hi[:, None, :], lo[:, None, :] - traj) / scale
    return np.maximum(excess.max(axis=(-3, -2, -1)), 0.0)


def constraint_violations(
    problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False
) -> tuple[Violation, ...]:
    """Every violated (joint, limit) pair for one ``k`` (scalar, or (n,) with
    ``per_joint=True``), worst first; empty when the halt is within all limits (eq. 33)."""
    t = problem.times(problem.n_check)
    lo, hi = _limits(problem)
    sl = _slack(lo, hi)
    traj = np.stack(problem.on_grid(k, problem.n_check, per_joint=per_joint))  # (3, n_t, n)
    over = traj - hi[:, None, :]
    under = lo[:, None, :] - traj
    out = []
    for kind_i, kind in enumerate(("angle", "velocity", "acceleration")):
        for j in range(problem.dof):
            for arr, lim in ((over, hi), (under, lo)):
                i_t = int(np.argmax(arr[kind_i, :, j]))
                excess = float(arr[kind_i, i_t, j])
                if excess > sl[kind_i, j]:
                    out.append(
                        Violation(
                            joint=problem.model.joint_numbers[j],
                            kind=kind,  # type: ignore[arg-type]
                            limit=float(lim[kind_i, j]),
                            value=float(traj[kind_i, i_t, j]),
                            excess=excess,
                            time=float(t[i_t]),
                        )
                    )
    return tuple(sorted(out, key=lambda v: -v.excess / max(abs(v.limit), 1e-300)))


def least_violating_k(problem: HaltProblem) -> float:
    """Shared ``k`` [rad/s^6] minimising the largest relative limit excess (a convex,
    piecewise-linear function of ``k``): dense scan, then bounded refinement.

    Both evaluate :func:`relative_violation` on the few limits that can be the largest
    somewhere in the stretch of ``k`` being evaluated (:class:`_Limits`): the same numbers, bit
    for bit, as evaluating every limit at every check time, in a fraction of the time.  The
    scan's stretches are found by halving the grid, each half keeping the limits its parent
    kept that can still be the largest in it (a limit never the largest in a stretch is never
    the largest in a part of it), so no step looks at every limit but the first."""
    per = feasible_k_intervals(problem)
    ends = per[np.isfinite(per)]
    span = max(float(np.abs(ends).max()) if ends.size else 0.0, 1e-12)
    grid = np.linspace(-2 * span, 2 * span, 801)
    limits = _Limits.of(problem).within(float(grid[0]), float(grid[-1]))

    def scan(kept: _Limits, part: FloatArray) -> FloatArray:  # ``kept``: pruned for ``part``
        if part.size <= SCAN_STRETCH:
            return kept.relative_violation(part)
        halves = part[: part.size // 2], part[part.size // 2 :]
        return np.concatenate([scan(kept.within(float(h[0]), float(h[-1])), h) for h in halves])

    if use_compiled(grid.size * limits.count, COMPILED_MIN_BATCH):  # the same numbers, one call (workers)
        from ... import _kernels

        viol = np.empty(grid.size)
        _kernels.least_violation_scan(
            limits.base, limits.shape, limits.lo, limits.hi, limits.scale, grid, SCAN_STRETCH, viol
        )
    else:
        viol = scan(limits, grid)
    i = int(np.argmin(viol))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    from scipy.optimize import minimize_scalar  # on first use: scipy.optimize takes ~0.5 s to import

    near = limits.within(float(a), float(b))
    res = minimize_scalar(
        lambda x: float(near.relative_violation(np.array([x]))[0]),
        bounds=(a, b),
        method="bounded",
        options={"xatol": 1e-12 * span + 1e-15},
    )
    return float(res.x) if res.fun <= viol[i] else float(grid[i])


#: Values of ``k`` of :func:`least_violating_k`'s scan whose binding limits are found together.
SCAN_STRETCH = 25


@dataclass(frozen=True)
class _Limits:
    """Every limit of a halt problem (kind, check time, joint) as the terms of
    :func:`relative_violation`, flat: ``traj = base + k * shape`` against ``[lo, hi]``, divided
    by ``scale``.  :meth:`within` keeps those that can be the largest excess somewhere in a
    stretch of ``k``; :meth:`relative_violation` evaluates them with the very operations of
    :func:`relative_violation`, so its value (a maximum: exact) is the same number.

    Why dropping is safe: on each side (upper, lower) a limit's relative excess is affine in
    ``k``, so over ``[k_lo, k_hi]`` it lies between its values at the two ends.  The largest
    excess is at least the largest of the sides' smaller end values, ``L``; a limit whose sides
    stay below ``L`` at both ends (less a margin far above round-off) is never the largest."""

    base: FloatArray  # (L,) the k = 0 angle, rate or acceleration [rad, rad/s, rad/s^2]
    shape: FloatArray  # (L,) its k-part phi, phi' or phi''
    lo: FloatArray  # (L,) the limits
    hi: FloatArray
    scale: FloatArray  # (L,) what an excess is relative to

    @classmethod
    def of(cls, problem: HaltProblem) -> _Limits:
        """Every limit of ``problem`` at every check time (3 x n_check x n)."""
        _, base_parts, shape_parts = problem.profiles(problem.n_check)
        lo, hi = _limits(problem)
        base = np.stack(base_parts)  # (3, n_t, n)
        shape = np.broadcast_to(np.stack(shape_parts)[..., None], base.shape)  # (3, n_t, n)
        scale = np.maximum(np.abs(lo), np.abs(hi))
        scale = np.where(np.isfinite(scale), scale, 1.0)[:, None, :]  # no angle limit: never exceeded
        full = np.broadcast_arrays(base, shape, lo[:, None, :], hi[:, None, :], scale)
        return cls(*(np.ascontiguousarray(x).reshape(-1) for x in full))

    @property
    def count(self) -> int:
        """Limits held."""
        return int(self.base.size)

    def within(self, k_lo: float, k_hi: float) -> _Limits:
        """The limits that can give the largest excess for some ``k`` in ``[k_lo, k_hi]``."""
        with np.errstate(invalid="ignore"):  # an infinite limit: -inf at both ends, never kept
            ends = []
            for k in (k_lo, k_hi):
                traj = self.base + k * self.shape
                ends.append(((traj - self.hi) / self.scale, (self.lo - traj) / self.scale))
            high = [np.maximum(a, b) for a, b in zip(*ends)]  # per side, its larger end value
            floor = max(float(np.minimum(a, b).max(initial=-np.inf)) for a, b in zip(*ends))
        if not np.isfinite(floor):
            return self
        # far above the round-off of each term (that of base + k * shape and of the limit, over
        # the scale); a NaN term is kept (the full scan's maximum is NaN then too)
        finite = [np.where(np.isfinite(x), np.abs(x), 0.0) for x in (self.lo, self.hi)]
        k_big = max(abs(k_lo), abs(k_hi))
        terms = np.abs(self.base) + k_big * np.abs(self.shape) + np.maximum(*finite)
        margin = 1e-6 * (1.0 + abs(floor)) + 64 * np.finfo(float).eps * terms / self.scale
        keep = ~((high[0] < floor - margin) & (high[1] < floor - margin))
        return _Limits(*(x[keep] for x in (self.base, self.shape, self.lo, self.hi, self.scale)))

    def relative_violation(self, k: FloatArray) -> FloatArray:
        """(m,) the largest relative excess (0 when within every limit) for ``k`` (m,)."""
        if self.count == 0:
            return np.zeros(k.shape)
        traj = self.base + k[:, None] * self.shape  # the operations of HaltProblem.trajectory
        excess = np.maximum(traj - self.hi, self.lo - traj) / self.scale
        return np.maximum(excess.max(axis=-1), 0.0)


def _start_breaks_limits(problem: HaltProblem) -> bool:
    """The state at failure itself is outside a limit (beyond the round-off slack): the halt
    starts from it (the ``k``-part and its first two derivatives vanish at ``t = 0``)."""
    lo, hi = _limits(problem)
    start = np.stack([problem.q0, problem.dq0, problem.ddq0])
    sl = _slack(lo, hi)
    return bool(np.any((start < lo - sl) | (start > hi + sl)))


def minimum_halt_time(
    problem: HaltProblem, *, t_min: float = 0.5, t_max: float | None = None, tol: float = 1e-3
) -> float | None:
    """Smallest halt time ``T`` [s] for which a feasible shared ``k`` exists.

    Scans ``T`` on a grid of 0.25 s steps from ``t_min`` to ``t_max`` (default
    ``max(10 T, 120 s)``), then bisects the first infeasible-to-feasible bracket to
    ``tol`` [s].  Returns None when no ``T`` in the range is feasible, at once when the state
    at failure itself breaks a limit (every halt starts from it, whatever ``T`` and ``k``).
    """
    if _start_breaks_limits(problem):
        return None  # the halt starts from this state whatever T and k: no T helps
    t_max = max(10 * problem.T, 120.0) if t_max is None else t_max
    grid = np.arange(t_min, t_max + 1e-9, 0.25)

    # in a worker, a halt time the screen on every check time proves infeasible (a fifth of
    # the exact check's cost, compiled) is not checked exactly: most of the bisection's
    # infeasible halves and of the scan's halt times the coarse screen let through
    fine_screen = use_compiled(1, COMPILED_MIN_BATCH)

    def ok(T: float) -> bool:
        if fine_screen and _surely_infeasible(problem, np.array([T]), stride=1)[0]:
            return False
        lo, hi = shared_k_interval(problem.with_time(T))
        return lo <= hi

    prev = None
    for first in range(0, grid.size, SCREEN_TIMES):
        chunk = grid[first : first + SCREEN_TIMES]
        # a screen on fewer check times proves most short halts infeasible at a fraction of the
        # cost; only the others are checked exactly, so the answer is the exact scan's
        surely_not = _surely_infeasible(problem, chunk)
        for T, skip in zip(chunk, surely_not):
            if not skip and ok(float(T)):
                if prev is None:
                    return float(T)
                # infeasible at prev, feasible at T: bisect the bracket to tol
                return float(bisect_boundary(lambda x: ok(float(x)), prev, float(T), xtol=tol).true_end)
            prev = float(T)
    return None


#: Halt times screened together by :func:`_surely_infeasible` in :func:`minimum_halt_time`.
SCREEN_TIMES = 16
#: Every this many check times are screened (the first and the last always).
SCREEN_STRIDE = 8
#: Relative error allowed for each bound of the screen, against the size of the terms it is
#: computed from (round-off is ~1e-16 of them): far above it, so the screen never claims
#: infeasible what the exact check finds feasible.
SCREEN_RTOL = 1e-10


def _surely_infeasible(problem: HaltProblem, halt_times: FloatArray, stride: int = SCREEN_STRIDE) -> np.ndarray:
    """(m,) bool: for each halt time (m,) [s], True where no shared ``k`` keeps the angle, rate
    and acceleration limits even at every ``stride``-th check time alone (and False where that
    is not certain).

    Fewer constraints give each ``k`` interval a superset of the exact one
    (:func:`feasible_k_intervals`), so an empty screened interval means an empty exact one.
    The screen's own arithmetic (every ``T`` at once) differs from the exact check's by
    round-off, so each bound is widened by :data:`SCREEN_RTOL` of the terms it comes from, and
    check times where ``phi`` or its derivative vanishes (no bound on ``k``) are left out."""
    n = problem.n_check
    picked = np.arange(0, n, stride)
    if picked[-1] != n - 1:
        picked = np.r_[picked, n - 1]  # the last check time always (sorted, unique: as np.unique made them)
    lo, hi = _limits(problem)
    if use_compiled(picked.size * np.size(halt_times), COMPILED_MIN_BATCH):  # a campaign's workers
        from ... import _kernels

        out = np.empty(np.size(halt_times), dtype=bool)
        _kernels.screen_k_bounds(
            np.asarray(halt_times, dtype=float).reshape(-1), picked, n, problem.q0, problem.dq0, problem.ddq0,
            problem.qf, lo, hi, SCREEN_RTOL, out,
        )  # fmt: skip
        return out
    T = np.asarray(halt_times, dtype=float)[:, None, None]  # (m, 1, 1)
    # the check times exactly as problem.times (np.linspace) makes them: i * (T / (n - 1)), the
    # last one T itself
    t = np.where(picked[None, :, None] == n - 1, T, picked[None, :, None] * (T / (n - 1)))  # (m, s, 1)
    q0, dq0, ddq0, qf = problem.q0, problem.dq0, problem.ddq0, problem.qf
    h = qf - q0
    # 000 eq. 27 with k = 0 (halt_coefficients), every T at once: (m, 1, n) each
    a3 = (20 * h - T**2 * 3 * ddq0 - T * 12 * dq0) / (2 * T**3)
    a4 = (T**2 * 3 * ddq0 + T * 16 * dq0 - 30 * h) / (2 * T**4)
    a5 = (-ddq0 * T**2 - 6 * dq0 * T + 12 * h) / (2 * T**5)
    terms = (
        (q0, dq0 * t, ddq0 / 2 * t**2, a3 * t**3, a4 * t**4, a5 * t**5),
        (dq0, ddq0 * t, 3 * a3 * t**2, 4 * a4 * t**3, 5 * a5 * t**4),
        (ddq0, 6 * a3 * t, 12 * a4 * t**2, 20 * a5 * t**3),
    )
    shapes = k_shape(t, T)  # phi and its derivatives, every T at once (T broadcasts)
    k_lo = np.full(T.shape[0], -np.inf)
    k_hi = np.full(T.shape[0], np.inf)
    for kind in range(3):
        base = sum(terms[kind])
        size = sum(np.abs(x) for x in terms[kind])
        phi = shapes[kind]
        bounds = np.abs(phi) > 0
        safe = np.where(bounds, phi, 1.0)
        with np.errstate(invalid="ignore", over="ignore"):  # infinite limits give no bound
            b1, b2 = (lo[kind] - base) / safe, (hi[kind] - base) / safe
            widen = SCREEN_RTOL * (size + np.maximum(np.abs(np.where(np.isfinite(lo[kind]), lo[kind], 0.0)),
                                                     np.abs(np.where(np.isfinite(hi[kind]), hi[kind], 0.0)))) / np.abs(safe)  # fmt: skip
            low = np.where(bounds & np.isfinite(b1 + b2), np.minimum(b1, b2) - widen, -np.inf)
            high = np.where(bounds & np.isfinite(b1 + b2), np.maximum(b1, b2) + widen, np.inf)
        k_lo = np.maximum(k_lo, low.max(axis=(1, 2)))
        k_hi = np.minimum(k_hi, high.min(axis=(1, 2)))
    return k_lo > k_hi
