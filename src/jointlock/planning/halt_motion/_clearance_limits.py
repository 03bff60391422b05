"""Clearance of a halt (issue 27): which values of the shared ``k`` give a halt motion that keeps
the clearance required between the arm's links, its spacecraft bus and keep-out volumes
(:func:`jointlock.collision.clearance`) on every sample of the constraint grid.

A pair that is already closer than required at the state at failure (the same for every ``k``:
the halt polynomial starts there) may not come closer still: its floor is its distance at
``t = 0``.  Like the torques, the clearance is not affine in ``k``, so its feasible set may be
several stretches: a scan of ``n_scan`` values, each feasible/infeasible boundary bisected to
:data:`BOUNDARY_RTOL` of the width (:func:`jointlock._search1d.bisect_boundary`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..._search1d import true_segments
from ...collision import clearance
from ...model import FloatArray
from ...shapes import Shape
from ._constants import CHUNK_SAMPLES
from ._problem import HaltProblem

#: Relative width of the refined boundaries of the clear set of ``k`` [-].
BOUNDARY_RTOL = 1e-9
#: Scan points of ``k`` for the clearance (each a whole motion on the constraint grid).
CLEARANCE_SCAN = 41
#: :func:`keeps_clearance` looks at every this many check times first.
SCREEN_STRIDE = 16


def clearance_shortfall(
    problem: HaltProblem, k: FloatArray, margin: float, keep_out: Sequence[Shape] = ()
) -> FloatArray:
    """(...) the largest amount [m] by which a halt at ``k`` (...) [rad/s^6] comes closer than
    allowed on the constraint grid (for each pair the smaller of its allowance, ``margin`` or 0
    for a mounted pair, and its distance at ``t = 0``); <= 0: clear."""
    k = np.asarray(k, dtype=float)
    flat = k.reshape(-1)
    t = problem.times(problem.n_check)
    floor = _floor(problem, margin, keep_out)
    return _shortfall_at(problem, flat, t, floor, keep_out).reshape(k.shape)


def _floor(problem: HaltProblem, margin: float, keep_out: Sequence[Shape]) -> FloatArray:
    """(P,) the distance each pair must keep [m] (see :func:`clearance_shortfall`)."""
    at_failure = clearance(problem.model, problem.q0, keep_out=keep_out)
    return np.minimum(np.where(at_failure.mounted_pairs, 0.0, margin), at_failure.pair_distance)


def _shortfall_at(
    problem: HaltProblem, k: FloatArray, t: FloatArray, floor: FloatArray, keep_out: Sequence[Shape]
) -> FloatArray:
    """(K,) the largest shortfall [m] of the halts at ``k`` (K,) over the times ``t`` (n_t,)."""
    out = np.empty(k.size)
    step = max(1, CHUNK_SAMPLES // t.size)
    for start in range(0, k.size, step):
        q, _, _ = problem.trajectory(k[start : start + step], t)
        distance = clearance(problem.model, q, keep_out=keep_out).pair_distance  # (K, n_t, P)
        out[start : start + step] = (floor - distance).max(axis=(-2, -1)) if distance.shape[-1] else -np.inf
    return out


def keeps_clearance(problem: HaltProblem, k: FloatArray, margin: float, keep_out: Sequence[Shape] = ()) -> np.ndarray:
    """(K,) bool: whether the halt at each ``k`` (K,) [rad/s^6] keeps the clearance on the whole
    constraint grid (``clearance_shortfall(...) <= 0``, the same answer).

    Every :data:`SCREEN_STRIDE`-th check time is looked at first: a halt that comes too close
    there does not keep it (most of a scan's colliding halts are caught so, at a fraction of the
    cost); only the others are checked at the remaining times.  A configuration's distances do
    not depend on the batch it is computed in, so the answer is that of the whole grid."""
    k = np.asarray(k, dtype=float).reshape(-1)
    t = problem.times(problem.n_check)
    floor = _floor(problem, margin, keep_out)
    screened = np.zeros(t.size, dtype=bool)
    screened[:: SCREEN_STRIDE] = True
    screened[-1] = True
    ok = _shortfall_at(problem, k, t[screened], floor, keep_out) <= 0.0
    if ok.any():
        ok[ok] = _shortfall_at(problem, k[ok], t[~screened], floor, keep_out) <= 0.0
    return ok


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
