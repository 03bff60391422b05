"""Robust choice of ``k`` (issue 14, item 3): among the values of ``k`` whose objective is within
a small share of the best, the one whose halt keeps the largest smallest margin to the speed,
acceleration and torque limits -- so that a halt optimal on paper does not sit on a limit when
a nearly as good one keeps clear of all of them."""

from __future__ import annotations

import numpy as np

from ...model import FloatArray
from ._actuator_limits import actuator_peaks
from ._objective import halt_objective
from ._problem import HaltProblem

#: Candidates per chunk of the margin scan (each holds the whole constraint grid).
_CHUNK = 32


def limit_margins(problem: HaltProblem, k: FloatArray) -> FloatArray:
    """(..., L) ``1 - peak / limit`` of every limit, for a batch of shared ``k`` [rad/s^6]: each
    joint's speed and acceleration limit, then each finite motor and brake torque limit, on
    the problem's constraint grid (negative: broken)."""
    k = np.asarray(k, dtype=float)
    flat = k.reshape(-1)
    parts = []
    for start in range(0, flat.size, _CHUNK):
        _, dq, ddq = problem.on_grid(flat[start : start + _CHUNK], problem.n_check)
        parts.append(
            np.concatenate(
                [1.0 - np.abs(dq).max(axis=-2) / problem.dq_max, 1.0 - np.abs(ddq).max(axis=-2) / problem.ddq_max],
                axis=-1,
            )
        )
    out = np.concatenate(parts)
    if problem.has_torque_limits:
        motor, brake, _ = actuator_peaks(problem, flat)
        tau_max, brake_max = problem.torque_limits()
        torque = np.concatenate([1.0 - motor / tau_max, 1.0 - brake / brake_max], axis=-1)
        out = np.concatenate([out, torque[:, np.isfinite(np.concatenate([tau_max, brake_max]))]], axis=-1)
    return out.reshape(k.shape + (-1,))


def prefer_margin(
    problem: HaltProblem, k_best: float, stretch: tuple[float, float], tolerance: float, n_scan: int
) -> float:
    """The ``k`` of ``stretch`` [rad/s^6] (the feasible stretch holding ``k_best``) whose limit
    margins are best, among those whose objective is at most ``(1 + tolerance)`` times the
    best one: the largest smallest margin, ties (a margin no ``k`` changes, e.g. a joint that
    starts at its speed limit) broken by the next smallest, and so on (leximin, margins
    compared to 1e-6); ``k_best`` itself when no other does better (``n_scan`` candidates)."""
    lo, hi = stretch
    if not tolerance or not hi > lo:
        return k_best
    grid = np.append(np.linspace(lo, hi, n_scan), k_best)
    best = float(halt_objective(problem, k_best))
    near = halt_objective(problem, grid) <= best + tolerance * abs(best)
    margins = np.round(np.sort(limit_margins(problem, grid), axis=-1), 6)[near]
    candidates = grid[near]
    order = np.lexsort(margins.T[::-1])  # ascending leximin: the last is the best
    i = int(order[-1])
    return float(candidates[i]) if not np.array_equal(margins[i], margins[-1]) else k_best
