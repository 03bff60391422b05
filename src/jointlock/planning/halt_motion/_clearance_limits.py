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


def clearance_shortfall(
    problem: HaltProblem, k: FloatArray, margin: float, keep_out: Sequence[Shape] = ()
) -> FloatArray:
    """(...) the largest amount [m] by which a halt at ``k`` (...) [rad/s^6] comes closer than
    allowed on the constraint grid (for each pair the smaller of its allowance, ``margin`` or 0
    for a mounted pair, and its distance at ``t = 0``); <= 0: clear."""
    k = np.asarray(k, dtype=float)
    flat = k.reshape(-1)
    t = problem.times(problem.n_check)
    at_failure = clearance(problem.model, problem.q0, keep_out=keep_out)
    floor = np.minimum(np.where(at_failure.mounted_pairs, 0.0, margin), at_failure.pair_distance)
    out = np.empty(flat.size)
    step = max(1, CHUNK_SAMPLES // t.size)
    for start in range(0, flat.size, step):
        q, _, _ = problem.trajectory(flat[start : start + step], t)
        distance = clearance(problem.model, q, keep_out=keep_out).pair_distance  # (K, n_t, P)
        out[start : start + step] = (floor - distance).max(axis=(-2, -1)) if distance.shape[-1] else -np.inf
    return out.reshape(k.shape)


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
        return clearance_shortfall(problem, x, margin, keep_out) <= 0.0

    return true_segments(clear, lo, hi, n_scan, BOUNDARY_RTOL)
