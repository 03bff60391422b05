"""Optimal kappa per failure time under the limits (:func:`search_kappa`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ScenarioError
from ...model import ArmModel, FloatArray
from ._engine import _branched_runs, _healthy_runs, _integrate, _kappa_rows, _ok, _Problem, _problem
from ._simulate import _table, jump_reduction
from ._task import JumpScenario

#: Golden ratio conjugate used by the bounded refinement.
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass(frozen=True)
class KappaSearch:
    """Optimal kappa per failure time (:func:`search_kappa`).

    Attributes
    ----------
    fail_times
        (F,) failure times [s] (multiples of dt).
    fail_steps
        (F,) their control steps.
    kappa_grid
        (K,) grid values searched.
    objective
        (K, F) ``||dqdot||`` [rad/s] at each grid value and failure time.
    feasible
        (K, F) every limit kept by the healthy run and by the run with the failure.
    interval
        (F, 2) feasible kappa interval (contiguous feasible grid run containing the optimum;
        resolution = grid step); NaN when none.
    kappa_opt
        (F,) optimal kappa (grid + golden-section refinement); NaN when infeasible.
    objective_opt, objective_zero
        (F,) ``||dqdot||`` at ``kappa_opt`` and at kappa = 0 [rad/s].
    zero_feasible
        (F,) kappa = 0 keeps every limit.
    probe_range
        (2,) kappa range ``[a, b]`` of the grid (where the healthy run keeps the limits).
    null_max
        Largest ``|(I - J^+J) grad w|_inf`` along the uncompensated run [rad/s per unit kappa].
    scenario
        The settings.
    options
        Keyword arguments of :func:`search_kappa` that reproduce this grid (used by
        :func:`fit_kappa` to add failure times around a breakpoint of kappa(t)).
    """

    fail_times: FloatArray
    fail_steps: np.ndarray
    kappa_grid: FloatArray
    objective: FloatArray
    feasible: np.ndarray
    interval: FloatArray
    kappa_opt: FloatArray
    objective_opt: FloatArray
    objective_zero: FloatArray
    zero_feasible: np.ndarray
    probe_range: FloatArray
    null_max: float
    scenario: JumpScenario
    options: Mapping[str, Any] = field(default_factory=dict)

    @property
    def reduction(self) -> FloatArray:
        """(F,) relative jump reduction ``1 - obj_opt / obj_zero``; NaN (undefined) where
        ``obj_zero`` is 0 (no jump to reduce), see :func:`jump_reduction`."""
        return jump_reduction(self.objective_zero, self.objective_opt)



def sample_failure_times(scenario: JumpScenario, n: int) -> FloatArray:
    """``n`` failure times uniform over the task (001 §4.3: 40), on the control grid,
    strictly inside ``(0, T)``: ``t_i = round(i T/(n+1) / dt) dt``, i = 1..n (duplicates removed)."""
    if n < 1:
        raise ScenarioError(f"number of failure times must be >= 1; got {n}")
    N = scenario.n_steps
    steps = np.unique(np.clip(np.round(np.arange(1, n + 1) * N / (n + 1)).astype(int), 1, N - 1))
    return steps * scenario.dt


def _probe(prob: _Problem) -> float:
    """Largest ``|(I - J^+ J) grad w|_inf`` along the kappa = 0 run (sets the kappa scale)."""
    out = _integrate(
        prob,
        np.zeros((1, prob.N)),
        prob.q0[None],
        None,
        np.zeros(1, dtype=int),
        np.full((1, 1), prob.N + 1),
        [prob.lock_col],
        null_norm=True,
    )
    return max(float(out.max_null[0]), 1e-12)


def _contiguous(mask: np.ndarray, i: int) -> tuple[int, int]:
    lo = hi = i
    while lo > 0 and mask[lo - 1]:
        lo -= 1
    while hi < mask.size - 1 and mask[hi + 1]:
        hi += 1
    return lo, hi


# Over 100 lines only through its docstring (the method); the steps are the helpers below.
def search_kappa(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    fail_times: ArrayLike | None = None,
    *,
    n_samples: int = 40,
    kappa_range: tuple[float, float] | None = None,
    n_probe: int = 41,
    n_grid: int = 17,
    refine_iter: int = 3,
    n_starts: int = 2,
    progress: Any = None,
) -> KappaSearch:
    """Optimal kappa for each failure time under the limits (NOTES-001 "Optimal kappa").

    1. *Probe*: ``n_probe`` values over ``kappa_range`` (default ``+-2 vmax / s`` with ``s`` the
       largest ``|(I - J^+J) grad w|`` along the uncompensated run), healthy runs only: the
       interval ``[a, b]`` around 0 where the healthy run keeps every limit.
    2. *Grid*: ``n_grid`` values over ``[a, b]`` (0 included), one healthy run per value (which
       gives the jump at every failure time) and one post-failure run per (value, failure
       time) for the limits, all batched.  Feasible interval per failure time = contiguous
       feasible run of grid values around the best one (resolution = grid step).
    3. *Refinement*: safeguarded parabolic interpolation of ``||dqdot||^2`` (nearly quadratic:
       ``dqdot`` is affine in kappa at a fixed configuration, NOTES-001 property 5) in the
       bracket of the best grid value, all failure times at once; a refined value is kept only
       if it lowers the objective and keeps every limit.  The refinement starts from the
       ``n_starts`` best feasible *local* minima of the grid objective, not only the best grid
       value: the objective can have a narrow valley between two grid values (``halt7``: the
       optimum near +2e-4 lies between the grid values 0 and 4e-4 and is 6x lower than the
       best grid value, at the band edge; with one start the search jumped to that edge for
       ``t_f >= 8.5 s`` -- a spurious branch switch that the kappa(t) fit could not follow).

    Parameters
    ----------
    model
        The arm.
    scenario
        Task, lock joint, limits (NOTES-001 default when omitted).
    fail_times
        (F,) failure times [s]; default ``n_samples`` uniform times (:func:`sample_failure_times`).
    n_samples
        Number of failure times when ``fail_times`` is omitted (001: 40).
    kappa_range
        ``(lo, hi)`` probed in step 1.
    n_probe, n_grid
        Sizes of the probe and of the grid (>= 3).
    refine_iter
        Refinement iterations (0: grid only, as in 001).
    n_starts
        Local grid minima refined per failure time (1: only the best grid value, the
        behaviour before multi-start).
    progress
        Optional :class:`jointlock.progress.Progress`-like object (``update()`` per time step).
    """
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    times = (
        sample_failure_times(sc, n_samples)
        if fail_times is None
        else np.atleast_1d(np.asarray(fail_times, float))
    )
    fsteps = sc.step_of(times)
    times = fsteps * sc.dt
    F = fsteps.size
    if n_grid < 3 or n_probe < 3:
        raise ScenarioError(f"n_grid and n_probe must be >= 3; got {n_grid}, {n_probe}")
    null_max = _probe(prob)
    if kappa_range is None:
        rng_ = np.array([-2.0, 2.0]) * sc.vmax / null_max
    else:
        rng_ = np.asarray(kappa_range, dtype=float)
    if rng_.shape != (2,) or not np.all(np.isfinite(rng_)) or rng_[0] >= rng_[1]:
        raise ScenarioError(f"kappa_range must be (lo, hi) with lo < hi; got {kappa_range!r}")
    probe = np.unique(np.concatenate([np.linspace(rng_[0], rng_[1], n_probe), [0.0]]))
    ph = _healthy_runs(prob, _kappa_rows(prob, probe))
    pok = _ok(prob, ph)
    a, b = _probe_band(probe, pok)
    grid = _grid(a, b, n_grid)
    K = grid.size
    krows = _kappa_rows(prob, grid)
    # one pass: the K healthy runs and the K F runs branching off them at the failure times
    healthy, post = _branched_runs(prob, krows, np.repeat(np.arange(K), F), np.tile(fsteps, K), progress)
    table = _table(prob, krows, healthy)
    objective = table.joint_jump_norm[:, fsteps]  # (K, F)
    post_ok = _ok(prob, post).reshape(K, F)
    feasible = post_ok & table.healthy_limits_ok[:, None]
    g0 = int(np.flatnonzero(grid == 0.0)[0])
    zero_feasible = feasible[g0].copy()
    objective_zero = objective[g0].copy()

    interval, kappa_opt, obj_opt, starts = _grid_starts(grid, objective, feasible, n_starts)

    if refine_iter > 0 and starts[0] and K > 1:
        _refine_starts(prob, fsteps, starts, refine_iter, kappa_opt, obj_opt, interval)
    return KappaSearch(
        times,
        fsteps,
        grid,
        objective,
        feasible,
        interval,
        kappa_opt,
        obj_opt,
        objective_zero,
        zero_feasible,
        np.array([a, b]),
        null_max,
        sc,
        {
            "kappa_range": None if kappa_range is None else tuple(float(v) for v in kappa_range),
            "n_probe": n_probe,
            "n_grid": n_grid,
            "refine_iter": refine_iter,
            "n_starts": n_starts,
        },
    )


def _probe_band(probe: FloatArray, pok: np.ndarray) -> tuple[float, float]:
    """Kappa band ``[a, b]`` of the grid from the probe values and their healthy-run feasibility
    (:func:`search_kappa` step 1)."""
    i0 = int(np.flatnonzero(probe == 0.0)[0])
    if pok[i0]:
        lo, hi = _contiguous(pok, i0)
        # the true edges lie between the last feasible and first infeasible probe values
        a = probe[max(lo - 1, 0)] if lo > 0 else probe[0]
        b = probe[min(hi + 1, probe.size - 1)] if hi < probe.size - 1 else probe[-1]
        a = 0.5 * (a + probe[lo]) if lo > 0 else a
        b = 0.5 * (b + probe[hi]) if hi < probe.size - 1 else b
    elif pok.any():
        best = int(np.flatnonzero(pok)[np.argmin(np.abs(probe[pok]))])
        lo, hi = _contiguous(pok, best)
        a, b = probe[lo], probe[hi]
    else:
        a = b = 0.0
    return a, b


def _grid(a: float, b: float, n_grid: int) -> FloatArray:
    """``n_grid`` kappa values over ``[a, b]`` and 0 (:func:`search_kappa` step 2), ascending.

    A value within round-off of 0 (``|kappa| <= 1e-12 (b - a)``, e.g. -4e-19 when 0 lies on the
    grid) is set to exactly 0 rather than kept beside it: two values 1e-18 apart make a bracket
    of the refinement whose parabola is drawn through round-off, and which one of the pair comes
    first -- hence the refined kappa -- then depended on the last bits of ``a`` and ``b``.
    """
    if not b > a:
        return np.array([0.0])
    grid = np.linspace(a, b, n_grid)
    grid[np.abs(grid) <= 1e-12 * (b - a)] = 0.0
    return np.unique(np.concatenate([grid, [0.0]]))


def _grid_starts(
    grid: FloatArray, objective: FloatArray, feasible: np.ndarray, n_starts: int
) -> tuple[FloatArray, FloatArray, FloatArray, tuple[list, ...]]:
    """Grid optimum per failure time and the refinement starts (:func:`search_kappa` step 2).

    Returns ``interval`` (F, 2), ``kappa_opt`` (F,), ``obj_opt`` (F,) (NaN where no grid value is
    feasible) and the starts ``(s_f, s_lo, s_x, s_hi, s_fx, s_run, s_flo, s_fhi)``: failure-time
    index, bracket, grid value, its objective, the contiguous feasible run around it and the
    objective at the bracket's ends (grid values too).
    """
    F = feasible.shape[1]
    interval = np.full((F, 2), np.nan)
    kappa_opt = np.full(F, np.nan)
    obj_opt = np.full(F, np.nan)
    # refinement starts: up to n_starts feasible local minima of the grid objective per time
    s_f, s_lo, s_x, s_hi, s_fx, s_run, s_flo, s_fhi = [], [], [], [], [], [], [], []
    for f in range(F):  # reads off contiguous feasible runs; no simulation in this loop
        feas = feasible[:, f]
        if not feas.any():
            continue
        obj_f = np.where(feas, objective[:, f], np.inf)
        best = int(np.argmin(obj_f))
        lo, hi = _contiguous(feas, best)
        interval[f] = grid[lo], grid[hi]
        kappa_opt[f] = grid[best]
        obj_opt[f] = objective[best, f]
        left = np.concatenate([[np.inf], obj_f[:-1]])
        right = np.concatenate([obj_f[1:], [np.inf]])
        minima = np.flatnonzero(feas & (obj_f <= left) & (obj_f <= right))
        minima = minima[np.argsort(obj_f[minima], kind="stable")][: max(int(n_starts), 1)]
        if best not in minima:
            minima = np.concatenate([[best], minima[:-1]])
        for i in map(int, minima):
            rlo, rhi = _contiguous(feas, i)
            s_f.append(f)
            ilo, ihi = max(i - 1, rlo), min(i + 1, rhi)
            s_lo.append(grid[ilo])
            s_x.append(grid[i])
            s_hi.append(grid[ihi])
            s_fx.append(objective[i, f])
            s_run.append((grid[rlo], grid[rhi]))
            s_flo.append(objective[ilo, f])
            s_fhi.append(objective[ihi, f])
    return interval, kappa_opt, obj_opt, (s_f, s_lo, s_x, s_hi, s_fx, s_run, s_flo, s_fhi)


def _refine_starts(
    prob: _Problem,
    fsteps: np.ndarray,
    starts: tuple[list, ...],
    refine_iter: int,
    kappa_opt: FloatArray,
    obj_opt: FloatArray,
    interval: FloatArray,
) -> None:
    """Refine the starts of :func:`_grid_starts` (:func:`search_kappa` step 3); a refined value
    replaces ``kappa_opt``, ``obj_opt`` and ``interval`` (in place) where it lowers the
    objective and keeps every limit."""
    s_f, s_lo, s_x, s_hi, s_fx, s_run, s_flo, s_fhi = starts
    sf = np.asarray(s_f)
    cand, fcand = _refine(
        prob,
        fsteps[sf],
        np.asarray(s_lo),
        np.asarray(s_x),
        np.asarray(s_hi),
        np.asarray(s_fx),
        refine_iter,
        fa=np.asarray(s_flo),
        fb=np.asarray(s_fhi),
    )
    better = fcand < obj_opt[sf]
    if better.any():
        rows = np.flatnonzero(better)
        krows_c = _kappa_rows(prob, cand[rows])
        h, p = _branched_runs(prob, krows_c, np.arange(rows.size), fsteps[sf[rows]])
        ok = _ok(prob, p) & _ok(prob, h)
        for r in rows[ok][np.argsort(-fcand[rows[ok]], kind="stable")]:  # best written last
            f = sf[r]
            if fcand[r] < obj_opt[f]:
                kappa_opt[f] = cand[r]
                obj_opt[f] = fcand[r]
                interval[f] = s_run[r]


def merge_searches(a: KappaSearch, b: KappaSearch) -> KappaSearch:
    """The samples of two searches on the same grid, sorted by failure time (``a`` wins on
    duplicates).  Raises :class:`~jointlock.errors.ScenarioError` if the grids differ."""
    if a.scenario != b.scenario or not np.array_equal(a.kappa_grid, b.kappa_grid):
        raise ScenarioError("merge_searches: the searches must share scenario and kappa grid")
    steps = np.concatenate([a.fail_steps, b.fail_steps])
    _, first = np.unique(steps, return_index=True)  # first occurrence: a before b
    idx = first[np.argsort(steps[first], kind="stable")]

    def cat(x: np.ndarray, y: np.ndarray, axis: int = 0) -> np.ndarray:
        return np.take(np.concatenate([x, y], axis=axis), idx, axis=axis)

    return KappaSearch(
        cat(a.fail_times, b.fail_times),
        cat(a.fail_steps, b.fail_steps),
        a.kappa_grid,
        cat(a.objective, b.objective, 1),
        cat(a.feasible, b.feasible, 1),
        cat(a.interval, b.interval),
        cat(a.kappa_opt, b.kappa_opt),
        cat(a.objective_opt, b.objective_opt),
        cat(a.objective_zero, b.objective_zero),
        cat(a.zero_feasible, b.zero_feasible),
        a.probe_range,
        a.null_max,
        a.scenario,
        a.options,
    )


def _refine(
    prob: _Problem,
    fsteps: np.ndarray,
    a: FloatArray,
    x: FloatArray,
    b: FloatArray,
    fx: FloatArray,
    iters: int,
    *,
    fa: FloatArray | None = None,
    fb: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Safeguarded parabolic minimisation of ``||dqdot||^2`` in ``[a, b]`` (one per failure
    time, all batched); ``x`` is the best known point with value ``fx``, ``fa`` and ``fb`` the
    values at ``a`` and ``b`` when known (the grid's: one pass of healthy runs fewer each).
    Each iteration is one pass of every row's healthy run; the iterations are sequential by
    nature (each bracket follows from the last value)."""
    k_stop = int(fsteps.max()) + 1
    rows = np.arange(fsteps.size)

    def obj(kap: FloatArray) -> FloatArray:
        out = _healthy_runs(prob, _kappa_rows(prob, kap), k_stop=k_stop)
        assert out.qd_plus is not None and out.qd is not None  # _healthy_runs records both
        return np.linalg.norm(out.qd_plus - out.qd, axis=-1)[rows, fsteps]

    a, b, x, fx = a.copy(), b.copy(), x.copy(), fx.copy()
    fa = obj(a) if fa is None else fa.copy()
    fb = obj(b) if fb is None else fb.copy()
    for _ in range(iters):
        ya, yx, yb = fa**2, fx**2, fb**2
        num = (x - a) ** 2 * (yx - yb) - (x - b) ** 2 * (yx - ya)
        den = (x - a) * (yx - yb) - (x - b) * (yx - ya)
        with np.errstate(divide="ignore", invalid="ignore"):
            u = x - 0.5 * num / den
        width = b - a
        golden = np.where(b - x > x - a, x + (1 - _GOLDEN) * (b - x), x - (1 - _GOLDEN) * (x - a))
        bad = ~np.isfinite(u) | (u <= a) | (u >= b) | (np.abs(u - x) < 1e-3 * np.maximum(width, 1e-300))
        u = np.where(bad, golden, u)
        fu = obj(u)
        win = fu < fx
        right = u > x
        # bracket update (golden-section style)
        a_new = np.where(win, np.where(right, x, a), np.where(right, a, u))
        b_new = np.where(win, np.where(right, b, x), np.where(right, u, b))
        fa_new = np.where(win, np.where(right, fx, fa), np.where(right, fa, fu))
        fb_new = np.where(win, np.where(right, fb, fx), np.where(right, fu, fb))
        x = np.where(win, u, x)
        fx = np.where(win, fu, fx)
        a, b, fa, fb = a_new, b_new, fa_new, fb_new
    return x, fx
