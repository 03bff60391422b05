"""Per-segment decisions of the piecewise kappa(t) (:func:`fit_kappa` step 4)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ...model import FloatArray
from ._engine import _healthy_runs, _Problem
from ._pieces import KappaPiece, _crossings, fit_pieces
from ._search import KappaSearch


def _jumps(prob: _Problem, fail_steps: np.ndarray, schedules: list[FloatArray], k_stop: int) -> FloatArray:
    """(S, F) ``||dqdot||`` at ``fail_steps`` in the healthy runs with the (N,) ``schedules``."""
    out = _healthy_runs(prob, np.stack(schedules), k_stop=k_stop)
    assert out.qd_plus is not None and out.qd is not None  # _healthy_runs records both
    return np.linalg.norm(out.qd_plus - out.qd, axis=-1)[:, fail_steps]


def _decide_segments(
    prob: _Problem,
    merged: KappaSearch,
    pieces: list[KappaPiece],
    *,
    order: int,
    max_order: int,
    threshold: float | None,
    rtol: float,
) -> tuple[FloatArray, list[KappaPiece], list[tuple[float, float, str]], np.ndarray, FloatArray | None]:
    """Per segment, in time order: own piece (trimmed or not), previous piece continued, or
    kappa = 0 (:func:`fit_kappa` step 4).

    Returns the schedule (N,), the kept pieces, the decisions ``(start, end, choice)``, the
    (F,) mask of the samples the kept pieces were fitted to and the (F,) ``||dqdot||`` [rad/s]
    at every sample with the schedule (the last segment's winning candidate *is* the schedule,
    and its jumps were computed at every sample; None when there is no piece).
    """
    t_all = merged.fail_times
    steps = prob.t[:-1]
    seg_of = np.searchsorted([pc.start for pc in pieces[1:]], t_all, side="right")  # segment of every sample
    feasible_in = np.all(np.isfinite(merged.interval), axis=1)
    kap = np.zeros(prob.N)
    kept: list[KappaPiece] = []
    decisions = []
    used = np.zeros(t_all.size, dtype=bool)
    jumps_kap: FloatArray | None = None
    for s, pc in enumerate(pieces):
        on = (steps >= pc.start) & ((steps < pc.end) | (s == len(pieces) - 1))
        here = (seg_of == s) & feasible_in
        k_stop = int(merged.fail_steps[seg_of == s].max()) + 1
        names = ["fit", "zero"]
        cands = [np.where(on, pc.polynomial(steps), kap), np.where(on, 0.0, kap)]
        if kept and kept[-1].end >= pc.start - 1e-12:  # the previous segment kept its piece
            names.append("continued")
            cands.append(np.where(on, kept[-1].polynomial(steps), kap))
        jm = _jumps(prob, merged.fail_steps, cands, k_stop)
        best_piece = pc
        # 001's segment points inside the piece: trim where the fit does not beat kappa = 0
        d = jm[0] - jm[1]
        pk = pc.polynomial(t_all)
        inside = (pk >= merged.interval[:, 0] - 1e-15) & (pk <= merged.interval[:, 1] + 1e-15)
        idx = np.flatnonzero(seg_of == s)
        trim = _trimmed_candidate(
            prob,
            merged,
            pc,
            idx,
            d,
            inside[idx] & feasible_in[idx],
            on,
            kap,
            k_stop,
            order=order,
            max_order=max_order,
            threshold=threshold,
            rtol=rtol,
        )
        trimmed = None
        if trim is not None:
            trimmed, cand, jt = trim
            names.append("trimmed")
            cands.append(cand)
            jm = np.concatenate([jm, jt])
        score = jm[:, here].mean(axis=1) if here.any() else jm[:, idx].mean(axis=1)
        # ties go to the simpler choice: zero before fit/continued
        pref = [1, 0] + list(range(2, len(names)))
        win = min(pref, key=lambda i: (score[i], pref.index(i)))
        choice = names[win]
        kap = cands[win]
        jumps_kap = jm[win]
        if choice == "fit":
            kept.append(best_piece)
            used[idx[np.isfinite(merged.kappa_opt[idx])]] = True
        elif choice == "trimmed":
            assert trimmed is not None  # "trimmed" is a candidate only when trim gave one
            kept.append(trimmed)
            used[
                idx[
                    np.isfinite(merged.kappa_opt[idx])
                    & (t_all[idx] >= trimmed.start)
                    & (t_all[idx] <= trimmed.end)
                ]
            ] = True
            choice = "fit"
        elif choice == "continued":
            kept[-1] = dataclasses.replace(kept[-1], end=pc.end, source="continued")
        decisions.append((float(pc.start), float(pc.end), choice))
    return kap, kept, decisions, used, jumps_kap


def _trimmed_candidate(
    prob: _Problem,
    merged: KappaSearch,
    pc: KappaPiece,
    idx: np.ndarray,
    d: FloatArray,
    usable: np.ndarray,
    on: np.ndarray,
    kap: FloatArray,
    k_stop: int,
    *,
    order: int,
    max_order: int,
    threshold: float | None,
    rtol: float,
) -> tuple[KappaPiece, FloatArray, FloatArray] | None:
    """The segment's piece trimmed to 001's segment points (``d = jump(fit) - jump(0)`` at the
    segment's samples ``idx``; ``usable``: those counted) and refitted on the samples inside:
    ``(piece, schedule, jumps)``, or ``None`` when there is nothing to trim."""
    sc = prob.scenario
    t_all = merged.fail_times
    steps = prob.t[:-1]
    seg = _crossings(t_all[idx], d[idx], usable, sc.duration)
    trim = None
    if np.isfinite(seg[0]):
        a_, b_ = (
            (pc.start if seg[0] <= t_all[idx[0]] else seg[0]),
            (pc.end if seg[1] >= t_all[idx[-1]] else seg[1]),
        )
        if (a_, b_) != (pc.start, pc.end):
            use = idx[np.isfinite(merged.kappa_opt[idx]) & (t_all[idx] >= a_) & (t_all[idx] <= b_)]
            if use.size >= 1:
                trimmed = fit_pieces(
                    t_all[use],
                    merged.kappa_opt[use],
                    order=order,
                    max_order=max_order,
                    threshold=threshold,
                    rtol=rtol,
                    span=(a_, b_),
                )[0]
                on_t = (steps >= a_) & ((steps < b_) | (b_ >= sc.duration))
                cand = np.where(on, np.where(on_t, trimmed.polynomial(steps), 0.0), kap)
                trim = trimmed, cand, _jumps(prob, merged.fail_steps, [cand], k_stop)
    return trim
