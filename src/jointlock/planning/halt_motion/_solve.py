"""The solvers of 000 eq. 34 (scan, GA, per-joint vector) and their result :class:`HaltMotion`."""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._cache import cached_on, state_without_cache
from ..._random import resolve_seed
from ...errors import InfeasibleError, ScenarioError
from ...model import FloatArray
from ..ga import GAResult, GASettings, adaptive_ga, bits_for_precision
from ._actuator_limits import (
    least_torque_violating_k,
    minimum_halt_time_with_torques,
    torque_feasible_segments,
    torque_violations,
)
from ._constants import K_UNIT_SCALE, TORQUE_FLOOR, Solver
from ._feasibility import (
    Violation,
    constraint_violations,
    feasible_k_intervals,
    least_violating_k,
    minimum_halt_time,
)
from ._objective import global_base_torque, halt_objective
from ._powell import powell_per_joint
from ._problem import HaltProblem
from ._report import infeasibility_message
from ._robust import prefer_margin as _prefer_margin

#: The package's logger (``jointlock.planning.halt_motion``), as before the split into modules.
log = logging.getLogger(__package__)


@dataclass(frozen=True)
class HaltMotion:
    """Optimal halt motion (000 eq. 34) and how it was found.

    Attributes
    ----------
    k
        Optimal coefficient [rad/s^6]: a float (shared, 000) or (n,) per joint.  When the
        problem is infeasible: the least-violating shared ``k``.
    global_torque
        ``tau_bar(k)`` [N m] (eq. 32).
    global_torque_k0
        ``tau_bar(0)`` [N m] (the plain quintic halt).
    feasible
        True when the halt at ``k`` respects every limit.
    violations
        Limits broken at ``k`` (empty when feasible); ``violations_k0`` at ``k = 0``.
    k_interval
        (2,) feasible interval of a shared ``k`` [rad/s^6] (``lo > hi``: empty).
    joint_intervals
        (n, 2) feasible interval of each joint's own ``k`` [rad/s^6].
    minimum_T
        Smallest halt time [s] with a feasible shared ``k`` (computed when infeasible or asked).
    solver
        ``"scan"``, ``"ga"`` or ``"vector"``.
    settings
        The solver's settings (grid size, GA settings, ...).
    seed
        Seed the GA ran with (solver ``"ga"``; the fresh one drawn for ``rng=None``), else None
        (a deterministic solver, an infeasible problem, or a ``Generator`` passed as ``rng``).
    problem
        The :class:`HaltProblem` solved.
    ga
        The GA run (solver ``"ga"``).
    k_optimum
        With ``prefer_margin``: the objective's own optimum [rad/s^6], when the chosen ``k``
        differs from it for a larger margin; else None.
    objective_value, objective_value_k0
        What was minimised (:attr:`HaltProblem.objective`, :func:`halt_objective`) at ``k`` and
        at ``k = 0`` (N m, or deg for the attitude change).
    k_segments
        With torque limits: the stretches ``(lo, hi)`` [rad/s^6] of ``k_interval`` whose halts
        also keep every motor and brake torque limit (empty: none does); None without them.
    """

    k: Any
    global_torque: float
    global_torque_k0: float
    feasible: bool
    violations: tuple[Violation, ...]
    violations_k0: tuple[Violation, ...]
    k_interval: FloatArray
    joint_intervals: FloatArray
    minimum_T: float | None
    solver: str
    settings: dict
    seed: int | None
    problem: HaltProblem = field(repr=False)
    ga: GAResult | None = field(default=None, repr=False)
    k_segments: tuple[tuple[float, float], ...] | None = None
    objective_value: float | None = None
    objective_value_k0: float | None = None
    k_optimum: float | None = None

    @property
    def feasible_stretch(self) -> tuple[float, float] | None:
        """The feasible stretch of a shared ``k`` holding the chosen one [rad/s^6]: the torque
        segment around it with torque limits, else :attr:`k_interval`; None when infeasible."""
        if not self.feasible or self.per_joint:
            return None
        if self.k_segments is not None:
            return next((s for s in self.k_segments if s[0] <= float(self.k) <= s[1]), None)
        return float(self.k_interval[0]), float(self.k_interval[1])

    @property
    def reduction(self) -> float:
        """Relative reduction of the global torque against ``k = 0`` [-] (000: 30.1 %).

        NaN when there is no torque at ``k = 0`` (``global_torque_k0 == 0``, e.g. a halt
        from rest to the start configuration): no relative reduction is defined then.
        """
        if self.global_torque_k0 == 0.0:
            return math.nan
        return 1.0 - self.global_torque / self.global_torque_k0

    @property
    def per_joint(self) -> bool:
        return np.ndim(self.k) == 1

    def trajectory(self, t: ArrayLike | None = None) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, dq, ddq (n_t, n) of the optimal halt."""
        return self.problem.trajectory(self.k, t, per_joint=self.per_joint)

    def __getstate__(self) -> dict[str, Any]:
        return state_without_cache(self)  # the cached trajectory is not pickled

    def check_trajectory(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """q, dq, ddq (n_check, n) of the optimal halt on the constraint grid
        (``problem.times(problem.n_check)``), read-only: computed once, as the margins, the
        clearance, the loads and the summary all look at it."""

        def compute() -> tuple[FloatArray, FloatArray, FloatArray]:
            sampled = self.problem.on_grid(self.k, self.problem.n_check, per_joint=self.per_joint)
            for x in sampled:
                x.setflags(write=False)
            return sampled

        return cached_on(self, "check_trajectory", compute)


def _scan(problem: HaltProblem, lo: float, hi: float, n_scan: int) -> tuple[float, FloatArray, FloatArray]:
    grid = np.linspace(lo, hi, n_scan)
    values = halt_objective(problem, grid)
    i = int(np.argmin(values))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, n_scan - 1)]
    best = float(grid[i])
    if b > a:
        from scipy.optimize import minimize_scalar  # on first use (slow to import)

        res = minimize_scalar(
            lambda x: float(halt_objective(problem, x)),
            bounds=(a, b),
            method="bounded",
            options={"xatol": 1e-9 * max(abs(hi - lo), 1e-30)},
        )
        if res.fun < values[i]:
            best = float(res.x)
    return best, grid, values


def _scan_segments(problem: HaltProblem, segments: Sequence[tuple[float, float]], n_scan: int) -> float:
    """:func:`_scan` over several stretches of ``k``, the scan's points shared by width (at
    least 3 each); the best of their optima."""
    total = sum(b - a for a, b in segments) or 1.0
    best = [_scan(problem, a, b, max(3, round(n_scan * (b - a) / total)))[0] for a, b in segments]
    values = halt_objective(problem, np.array(best))
    return float(best[int(np.argmin(values))])


def _check_k_bounds(k_bounds: Sequence[float] | None) -> tuple[float, float] | None:
    """``k_bounds`` as ``(lo, hi)`` [rad/s^6]: two numbers, not NaN, ``lo <= hi`` (infinite
    ends allowed: one-sided bounds)."""
    if k_bounds is None:
        return None
    try:
        arr = np.asarray(k_bounds, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"k_bounds must be two numbers (lo, hi) [rad/s^6]; got {k_bounds!r}") from None
    if arr.shape != (2,) or np.any(np.isnan(arr)):
        raise ScenarioError(f"k_bounds must be two numbers (lo, hi) [rad/s^6], not NaN; got {k_bounds!r}")
    if not arr[0] <= arr[1]:
        raise ScenarioError(f"k_bounds must satisfy lo <= hi [rad/s^6]; got {arr.tolist()}")
    return float(arr[0]), float(arr[1])


def _search_interval(per: FloatArray, bounds_k: tuple[float, float] | None) -> tuple[float, float]:
    """The shared-``k`` feasible interval of the joints' intervals ``per`` (n, 2), intersected
    with ``bounds_k`` [rad/s^6]; bounds that miss a non-empty feasible interval raise."""
    lo, hi = float(per[:, 0].max()), float(per[:, 1].min())
    if bounds_k is not None:
        if lo <= hi and not (bounds_k[0] <= hi and bounds_k[1] >= lo):
            scale = K_UNIT_SCALE["deg/s^6"]
            raise ScenarioError(
                f"k_bounds [{bounds_k[0]:.6g}, {bounds_k[1]:.6g}] rad/s^6 "
                f"([{bounds_k[0] / scale:.6g}, {bounds_k[1] / scale:.6g}] deg/s^6) miss the feasible "
                f"interval of k [{lo:.6g}, {hi:.6g}] rad/s^6 ([{lo / scale:.6g}, {hi / scale:.6g}] "
                "deg/s^6): no k within the bounds respects the limits; widen k_bounds or leave them out"
            )
        lo, hi = max(lo, bounds_k[0]), min(hi, bounds_k[1])
    return lo, hi


def _infeasible_result(
    problem: HaltProblem,
    solver: str,
    per: FloatArray,
    interval: tuple[float, float],
    k0: tuple[float, tuple[Violation, ...]],
    settings: dict[str, Any],
    on_infeasible: Literal["report", "raise"],
    *,
    torques_only: bool = False,
) -> HaltMotion:
    """The report of a problem without a feasible ``k``: least-violating ``k``, its violations
    and the smallest feasible ``T`` (with the torque limits when there are any); raised when
    ``on_infeasible="raise"``.  ``interval`` is empty, or (``torques_only``) the speed and
    acceleration limits' interval, every ``k`` of which breaks a torque limit."""
    torques = problem.has_torque_limits
    if torques_only:
        k = least_torque_violating_k(problem, interval[0], interval[1], settings["n_scan"])
    else:
        k = least_violating_k(problem)
    viol = constraint_violations(problem, k)
    if torques:
        viol = torque_violations(problem, k) + viol if torques_only else viol + torque_violations(problem, k)
    result = HaltMotion(
        k=k,
        global_torque=float(global_base_torque(problem, k)),
        global_torque_k0=k0[0],
        feasible=False,
        violations=viol,
        violations_k0=k0[1],
        k_interval=np.array(interval),
        joint_intervals=per,
        minimum_T=minimum_halt_time_with_torques(problem) if torques else minimum_halt_time(problem),
        solver=solver,
        settings=settings,
        seed=None,
        problem=problem,
        k_segments=() if torques_only else None,
        objective_value=float(halt_objective(problem, k)),
        objective_value_k0=float(halt_objective(problem, 0.0)),
    )
    msg = infeasibility_message(result)
    log.info("infeasible halt: %s", msg.splitlines()[0])
    if on_infeasible == "raise":
        raise InfeasibleError(msg)
    return result


def _solve_ga(
    problem: HaltProblem,
    lo: float,
    hi: float,
    ga_settings: GASettings | None,
    ga_precision: float | None,
    rng: int | np.random.Generator,
    progress: Any,
) -> tuple[GAResult, GASettings]:
    """000's adaptive GA on ``[lo, hi]`` with fitness ``1 / tau_bar`` (eq. 35), and the
    settings it ran with."""
    st = ga_settings or GASettings()
    if ga_precision is not None and hi > lo:
        st = replace(st, n_bits=bits_for_precision(lo, hi, ga_precision))
    ga_result = adaptive_ga(
        # eq. 35; the floor keeps the fitness finite where the torque vanishes
        lambda x: 1.0 / np.maximum(halt_objective(problem, x[:, 0]), TORQUE_FLOOR),
        lo,
        hi,
        settings=st,
        rng=rng,
        progress=progress,
    )
    return ga_result, st


def _solve_vector(
    problem: HaltProblem, per: FloatArray, lo: float, hi: float, k: float
) -> tuple[Any, dict[str, Any]]:
    """One ``k`` per joint: Powell within each joint's interval ``per`` (n, 2), started from
    the shared optimum ``k``; the shared ``k`` (as (n,)) is kept when Powell does not beat it.
    Returns the (n,) ``k`` [rad/s^6] and scipy's record."""
    x0 = np.clip(np.full(problem.dof, k), per[:, 0], per[:, 1])
    kv, record = powell_per_joint(
        lambda kk: float(halt_objective(problem, kk, per_joint=True)), x0, per, max(hi - lo, 1e-12)
    )
    best = (
        kv
        if halt_objective(problem, kv, per_joint=True) <= halt_objective(problem, k)
        else np.full(problem.dof, k)
    )
    return best, record


def optimal_halt_motion(
    problem: HaltProblem,
    *,
    solver: Solver = "scan",
    k_bounds: Sequence[float] | None = None,
    n_scan: int = 401,
    ga_settings: GASettings | None = None,
    ga_precision: float | None = None,
    rng: int | np.random.Generator | None = None,
    on_infeasible: Literal["report", "raise"] = "report",
    find_minimum_T: bool = False,
    progress: Any = None,
    prefer_margin: float = 0.0,
) -> HaltMotion:
    """Solve 000's halt-motion model (eq. 34): ``min tau_bar(k)`` s.t. the limits of eq. 33.

    Parameters
    ----------
    problem
        The halt problem.
    solver
        ``"scan"``: exact for a shared ``k`` -- ``n_scan`` points over the feasible interval,
        then bounded 1-D refinement (scipy ``minimize_scalar``) around the best point.
        ``"ga"``: 000's adaptive GA (:func:`jointlock.planning.ga.adaptive_ga`) on the
        feasible interval, fitness ``1 / tau_bar`` (eq. 35).  ``"vector"``: one ``k`` per
        joint (extension), scipy ``minimize`` (Powell, bounded by each joint's feasible
        interval) started from the shared-``k`` optimum.
    k_bounds
        ``(lo, hi)`` [rad/s^6] to intersect with the feasible interval (e.g. 000's
        Fig. 8 range ``[0, 0.1]`` deg/s^6); ``lo <= hi``, not NaN (an infinite end leaves
        that side open).  Default: the feasible interval itself.  Bounds that miss a
        non-empty feasible interval raise :class:`~jointlock.errors.ScenarioError` (giving
        both intervals); for an infeasible problem they do not change the report.
    n_scan
        Grid points of the scan, an integer >= 1.
    ga_settings, ga_precision
        GA settings; ``ga_precision`` [rad/s^6] sets the bits per gene (default: 1/1000 of
        the interval, 10 bits).
    rng
        Seed (int >= 0) or ``numpy.random.Generator`` of the GA (:mod:`jointlock._random`);
        ``None`` draws a fresh seed.  The GA's seed is recorded in ``seed``; checked whatever
        the solver (a bad value raises :class:`~jointlock.errors.ConfigurationError`), used
        only by ``"ga"``.
    on_infeasible
        ``"report"``: return a result with ``feasible=False``, the least-violating ``k``, the
        violations and the smallest feasible ``T``; ``"raise"``: raise
        :class:`~jointlock.errors.InfeasibleError` with the same information.
    find_minimum_T
        Also compute the smallest feasible halt time when the problem is feasible.
    prefer_margin
        A share of the best objective (>= 0; e.g. 0.01: 1 %): among the shared ``k`` of the
        feasible stretch holding the optimum whose objective is within it, the one with the
        largest smallest margin to the speed, acceleration and torque limits
        (:func:`~._robust.prefer_margin`; ``n_scan`` candidates).  0 (default): the optimum.

    Returns
    -------
    HaltMotion
    """
    if solver not in ("scan", "ga", "vector"):
        raise ScenarioError(f"solver must be 'scan', 'ga' or 'vector'; got {solver!r}")
    if isinstance(n_scan, bool) or not isinstance(n_scan, (int, np.integer)) or n_scan < 1:
        raise ScenarioError(f"n_scan must be an integer >= 1 (grid points of the scan); got {n_scan!r}")
    if not (isinstance(prefer_margin, (int, float)) and math.isfinite(prefer_margin) and prefer_margin >= 0):
        raise ScenarioError(f"prefer_margin must be a finite share >= 0 of the best objective; got {prefer_margin!r}")
    bounds_k = _check_k_bounds(k_bounds)
    rng = resolve_seed(rng)  # None -> a fresh int seed, recorded by the GA
    torques = problem.has_torque_limits
    if prefer_margin and solver == "vector":
        raise ScenarioError(
            "prefer_margin needs one shared k (solver 'scan' or 'ga'): the per-joint vector solver has no "
            "stretch of k to choose along"
        )
    if torques and solver != "scan":
        raise ScenarioError(
            f"motor and brake torque limits need solver 'scan' (got {solver!r}): the torques are not affine "
            "in k, and only the scan finds every stretch of k that keeps them"
        )
    per = feasible_k_intervals(problem)
    lo, hi = _search_interval(per, bounds_k)
    tau0 = float(global_base_torque(problem, 0.0))
    viol0 = constraint_violations(problem, 0.0)
    if torques:
        viol0 = viol0 + torque_violations(problem, 0.0)
    settings: dict[str, Any] = {"n_scan": n_scan, "n_samples": problem.n_samples, "n_check": problem.n_check}
    if not lo <= hi:
        return _infeasible_result(problem, solver, per, (lo, hi), (tau0, viol0), settings, on_infeasible)

    ga_result = None
    seed = None
    segments = None
    if torques:
        segments = tuple(torque_feasible_segments(problem, lo, hi, n_scan))
        if not segments:
            return _infeasible_result(
                problem, solver, per, (lo, hi), (tau0, viol0), settings, on_infeasible, torques_only=True
            )
        k: Any = _scan_segments(problem, segments, n_scan)
    elif solver == "ga":
        ga_result, settings["ga"] = _solve_ga(problem, lo, hi, ga_settings, ga_precision, rng, progress)
        k = float(ga_result.x[0])
        seed = ga_result.seed
    else:
        k, _, _ = _scan(problem, lo, hi, n_scan)
        if solver == "vector":
            k, settings["scipy"] = _solve_vector(problem, per, lo, hi, k)
    per_joint = np.ndim(k) == 1
    k_optimum = None
    if prefer_margin and not per_joint:
        stretch = (lo, hi) if segments is None else next(s for s in segments if s[0] <= k <= s[1])
        robust = _prefer_margin(problem, float(k), stretch, prefer_margin, n_scan)
        if robust != k:
            k_optimum, k = float(k), robust
        settings["prefer_margin"] = prefer_margin
    tau = float(global_base_torque(problem, k, per_joint=per_joint))
    viol = constraint_violations(problem, k, per_joint=per_joint)
    if torques:
        viol = torque_violations(problem, k) + viol
    if find_minimum_T:
        t_min = minimum_halt_time_with_torques(problem) if torques else minimum_halt_time(problem)
    return HaltMotion(
        k=k,
        global_torque=tau,
        global_torque_k0=tau0,
        feasible=not viol,
        violations=viol,
        violations_k0=viol0,
        k_interval=np.array([lo, hi]),
        joint_intervals=per,
        minimum_T=t_min if find_minimum_T else None,
        solver=solver,
        settings=settings,
        seed=seed,
        problem=problem,
        ga=ga_result,
        k_segments=segments,
        objective_value=float(halt_objective(problem, k, per_joint=per_joint)),
        objective_value_k0=float(halt_objective(problem, 0.0)),
        k_optimum=k_optimum,
    )
