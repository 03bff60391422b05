"""Piecewise kappa(t) fitted to the sampled optimum (:func:`fit_kappa`; 001 §3.3, §4.3)."""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from ...errors import InfeasibleError
from ...model import ArmModel, FloatArray
from ._engine import _healthy_runs, _kappa_rows, _problem
from ._pieces import KappaPiece, _crossings, _eval_pieces, _polyfit, find_breaks, fit_pieces
from ._search import KappaSearch, merge_searches, search_kappa
from ._segments import _decide_segments, _jumps

log = logging.getLogger(__package__)


@dataclass(frozen=True)
class KappaFit:
    """Fitted kappa(t) and its piecewise form (001 §3.3, §4.3; NOTES-001 "Unknown failure time").

    ``kappa(t)`` is the sum of :attr:`pieces`, each a polynomial on its span, and 0 outside
    every piece.  With one segment this is 001's form: ``p(t)`` between the two segment
    points, 0 near the start and the end.

    Attributes
    ----------
    order
        Highest polynomial order among the pieces (the single polynomial's order when
        ``piecewise=False`` or when no piece is kept).
    coefficients
        (order + 1,) the *single* least-squares polynomial in ``tau = t/T`` over every
        feasible sample (001's form; kept for comparison, see :meth:`polynomial`).
    ssr
        Sum of squared residuals over the samples used [kappa^2] (sum over the pieces).
    threshold
        Acceptance threshold on ``ssr`` (001's criterion; sum over the pieces).
    accepted
        Every piece meets its criterion at ``order <= max_order``.
    segment_points
        (2,) ``t1, t2`` [s]: start of the first and end of the last piece (NaN, NaN when
        compensation never helps: kappa(t) = 0).
    used
        (F,) samples used by the pieces' fits.
    objective_fit, objective_zero
        (F,) ``||dqdot||`` at the samples with the fitted schedule (history included: the
        healthy run with kappa(t) up to the failure) and with kappa = 0 [rad/s].  With
        ``piecewise=False``: with the constant kappa = p(t_i), as before.
    duration
        ``T`` [s].
    pieces
        The :class:`KappaPiece` list, in time order (empty: kappa(t) = 0, or the single form).
    breaks
        Times [s] where the sampled optimum jumps (segment boundaries).
    search
        The search with the failure times added around the breaks (``None``: none added).
    segments
        One entry per segment of the samples: ``(start, end, decision)`` with decision
        ``"fit"``, ``"continued"`` or ``"zero"``.
    """

    order: int
    coefficients: FloatArray
    ssr: float
    threshold: float
    accepted: bool
    segment_points: FloatArray
    used: np.ndarray
    objective_fit: FloatArray
    objective_zero: FloatArray
    duration: float
    pieces: tuple[KappaPiece, ...] | None = None
    breaks: FloatArray = field(default_factory=lambda: np.zeros(0))
    search: KappaSearch | None = None
    segments: tuple[tuple[float, float, str], ...] = ()

    def polynomial(self, t: ArrayLike) -> FloatArray:
        """The single polynomial ``p(t/T)`` (001's form), without segments or pieces."""
        tau = np.asarray(t, dtype=float) / self.duration
        return cast(FloatArray, np.polynomial.polynomial.polyval(tau, self.coefficients))

    def __call__(self, t: ArrayLike) -> FloatArray:
        """Piecewise kappa(t): each piece on its span, 0 elsewhere."""
        t = np.asarray(t, dtype=float)
        if self.pieces is None:  # single form (piecewise=False)
            t1, t2 = self.segment_points
            if not np.isfinite(t1):
                return np.zeros_like(t)
            return np.where((t >= t1) & (t <= t2), self.polynomial(t), 0.0)
        return _eval_pieces(self.pieces, t, self.duration)



def _feasible_samples(search: KappaSearch) -> np.ndarray:
    """Mask of the failure times with a feasible kappa; raise when fewer than two (no fit)."""
    finite = np.isfinite(search.kappa_opt)
    if finite.sum() < 2:
        raise InfeasibleError(
            f"fit_kappa: only {int(finite.sum())} failure time(s) have a feasible kappa; need >= 2 to fit kappa(t)"
        )
    return finite


# Over 100 lines only through its docstring (the method); the steps are the helpers it calls.
def fit_kappa(
    model: ArmModel,
    search: KappaSearch,
    *,
    order: int = 5,
    max_order: int = 9,
    threshold: float | None = None,
    rtol: float = 0.1,
    piecewise: bool = True,
    jump_rtol: float = 0.1,
    jump_factor: float = 10.0,
    refine_breaks: bool = True,
    max_refine: int = 7,
    refine_rounds: int = 2,
) -> KappaFit:
    """Fit kappa(t) to the optimal kappa per failure time (001 §3.3 and §4.3), piecewise.

    The sampled optimum need not be smooth: it can switch branch from one failure time to the
    next (another local minimum of ``||dqdot||(kappa)`` wins, or the feasible band cuts one
    off).  One polynomial cannot follow such a step and ends up far from both branches (on
    ``halt7`` with the single-start search it made the jumps 4.5x larger).  So:

    1. *Breaks*: consecutive samples whose optimum jumps (:func:`find_breaks`: more than
       ``jump_rtol`` of the searched kappa range and ``jump_factor`` times the median step).
    2. *Refinement*: new failure times are searched between the two samples of each break
       (up to ``max_refine`` control steps, evenly spaced; ``refine_rounds`` rounds), so the
       break is located to a control step where the samples allow (001: "add samples").
    3. *Pieces*: one least-squares polynomial per segment between breaks (:func:`fit_pieces`;
       order from ``order`` raised to ``max_order`` until ``SSR <= threshold``, 001's
       criterion, per segment).
    4. *Decisions*, segment by segment in time order, each judged by the jumps at the
       segment's sampled failure times in the **healthy run with the schedule decided so far**
       (the jump at ``t_f`` depends on kappa over ``[0, t_f]``, not only on ``kappa(t_f)``; an
       optimum sampled with a constant kappa since ``t = 0`` can be useless after a different
       history): the segment's own piece; the previous piece continued (when a piece
       precedes); or kappa = 0.  The lowest mean jump wins; so kappa falls back to 0 on a
       segment where the fit does not beat kappa = 0.  A kept own piece is then trimmed to
       001's segment points: where ``d_i = ||dqdot||(fit) - ||dqdot||(kappa = 0)`` crosses
       zero, first/last crossing into ``d < 0`` (linear interpolation; samples whose fitted
       kappa lies outside their feasible interval do not count), refitted on the samples
       inside (001 drops the erratic end samples) and kept if that lowers the mean jump.

    Without breaks, this is 001's single polynomial with segment points (same result as
    ``piecewise=False`` up to the history-consistent comparison).  The verification
    (:func:`verify_kappa`) then injects the failure at *every* control step, including the
    steps between samples, which the decisions never looked at.

    Parameters
    ----------
    model
        The arm of the search.
    search
        Result of :func:`search_kappa`.
    order, max_order
        Starting and largest polynomial order (001: 5).
    threshold
        Absolute SSR threshold (per piece); ``None`` uses ``rtol``.
    rtol
        Relative threshold (fraction of the samples' spread, per piece).
    piecewise
        ``False``: the single polynomial of 001 with its two segment points (no breaks,
        decisions with constant-kappa runs), the behaviour before piecewise fitting.
    jump_rtol, jump_factor
        Break detection (:func:`find_breaks`).
    refine_breaks, max_refine, refine_rounds
        Sample refinement around the breaks (needs ``search.options``).
    """
    if not piecewise:
        return _fit_single(model, search, order=order, max_order=max_order, threshold=threshold, rtol=rtol)
    sc = search.scenario
    prob = _problem(model, sc)
    finite = _feasible_samples(search)
    width = float(search.probe_range[1] - search.probe_range[0]) or 1.0
    single = _polyfit(
        search.fail_times[finite] / sc.duration, search.kappa_opt[finite], order, max_order, threshold, rtol
    )

    merged, added, fin, cuts = _refine_breaks(
        model,
        search,
        width,
        jump_rtol=jump_rtol,
        jump_factor=jump_factor,
        rounds=refine_rounds if refine_breaks else 0,
        max_refine=max_refine,
    )
    t_all = merged.fail_times
    t_s, k_s = t_all[fin], merged.kappa_opt[fin]
    pieces = fit_pieces(
        t_s,
        k_s,
        cuts,
        order=order,
        max_order=max_order,
        threshold=threshold,
        rtol=rtol,
        span=(0.0, sc.duration),
    )
    kap, kept, decisions, used, obj_fit = _decide_segments(
        prob, merged, pieces, order=order, max_order=max_order, threshold=threshold, rtol=rtol
    )
    if obj_fit is None:
        obj_fit = _jumps(prob, merged.fail_steps, [kap], int(merged.fail_steps.max()) + 1)[0]
    seg_pts = np.array([kept[0].start, kept[-1].end]) if kept else np.array([np.nan, np.nan])
    if kept:
        ordr = max(pc.order for pc in kept)
        ssr = float(sum(pc.ssr for pc in kept))
        thr = float(sum(pc.threshold for pc in kept))
        acc = all(pc.accepted for pc in kept)
    else:
        ordr, ssr, thr, acc = int(single[0]), float(single[2]), float(single[3]), bool(single[4])
    break_times = 0.5 * (t_s[cuts] + t_s[cuts + 1]) if cuts.size else np.zeros(0)
    return KappaFit(
        int(ordr),
        single[1],
        ssr,
        thr,
        bool(acc),
        seg_pts,
        used,
        obj_fit,
        merged.objective_zero,
        sc.duration,
        tuple(kept),
        break_times,
        merged if added else None,
        tuple(decisions),
    )


def _breaks_of(
    s: KappaSearch, width: float, jump_rtol: float, jump_factor: float
) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the samples with a feasible kappa, and the breaks among them (:func:`find_breaks`)."""
    fin = np.flatnonzero(np.isfinite(s.kappa_opt))
    return fin, find_breaks(s.kappa_opt[fin], width, jump_rtol=jump_rtol, jump_factor=jump_factor)


def _refine_breaks(
    model: ArmModel,
    search: KappaSearch,
    width: float,
    *,
    jump_rtol: float,
    jump_factor: float,
    rounds: int,
    max_refine: int,
) -> tuple[KappaSearch, bool, np.ndarray, np.ndarray]:
    """Search new failure times between the two samples of each break (:func:`fit_kappa` step 2).

    Returns the merged search, whether samples were added, and :func:`_breaks_of` of the
    merged search.
    """
    sc = search.scenario
    merged = search
    added = False
    fin, cuts = _breaks_of(merged, width, jump_rtol, jump_factor)
    for _ in range(rounds):
        extra = []
        for c in cuts:
            k_a, k_b = merged.fail_steps[fin[c]], merged.fail_steps[fin[c + 1]]
            if k_b - k_a > 1:
                extra.append(
                    np.unique(np.round(np.linspace(k_a, k_b, min(k_b - k_a - 1, max_refine) + 2)[1:-1]))
                )
        if not extra:
            break
        more = search_kappa(model, sc, np.concatenate(extra) * sc.dt, **dict(merged.options))
        if not np.array_equal(more.kappa_grid, merged.kappa_grid):  # options not reproducible
            log.warning("fit_kappa: refined search used another grid; breaks not refined")
            break
        merged = merge_searches(merged, more)
        added = True
        fin, cuts = _breaks_of(merged, width, jump_rtol, jump_factor)
    return merged, added, fin, cuts


def _fit_single(
    model: ArmModel,
    search: KappaSearch,
    *,
    order: int = 5,
    max_order: int = 9,
    threshold: float | None = None,
    rtol: float = 0.1,
) -> KappaFit:
    """001's single polynomial with two segment points (``fit_kappa(..., piecewise=False)``)."""
    sc = search.scenario
    prob = _problem(model, sc)
    t = search.fail_times
    finite = _feasible_samples(search)
    tau = t / sc.duration
    used = finite.copy()
    res = None
    for _ in range(2):
        ordr, coef, ssr, thr, acc = _polyfit(
            tau[used], search.kappa_opt[used], order, max_order, threshold, rtol
        )
        pk = np.polynomial.polynomial.polyval(tau, coef)
        table = _healthy_runs(prob, _kappa_rows(prob, pk), k_stop=int(search.fail_steps.max()) + 1)
        assert table.qd_plus is not None and table.qd is not None  # _healthy_runs records both
        obj_fit = np.linalg.norm(table.qd_plus - table.qd, axis=-1)[np.arange(t.size), search.fail_steps]
        d = obj_fit - search.objective_zero
        inside = (pk >= search.interval[:, 0] - 1e-15) & (pk <= search.interval[:, 1] + 1e-15)
        seg = _crossings(t, d, inside, sc.duration)
        res = (ordr, coef, ssr, thr, acc, seg, used.copy(), obj_fit)
        if not np.isfinite(seg[0]):
            break
        new_used = finite & (t >= seg[0]) & (t <= seg[1])
        if new_used.sum() < 2 or np.array_equal(new_used, used):
            break
        used = new_used
    assert res is not None  # the loop runs at least once
    ordr, coef, ssr, thr, acc, seg, used, obj_fit = res
    return KappaFit(
        int(ordr), coef, ssr, float(thr), bool(acc), seg, used, obj_fit, search.objective_zero, sc.duration
    )
