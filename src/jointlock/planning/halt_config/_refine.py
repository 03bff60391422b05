"""Beyond 000: the bounded local refinement of the best samples (L-BFGS-B on CP with its
normalisation and weights frozen, central-difference gradients in one batched call), keeping
the reachability constraint."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...model import FloatArray
from ._reachability import HaltReachability

#: Central-difference step of the refinement's gradient [rad]; CP is smooth away from
#: singular-value crossings, truncation error ~ h^2 (1e-12), round-off ~ eps / h (1e-10).
REFINE_FD_STEP = 1e-6


def _refine(
    cp_of: Callable[[FloatArray], FloatArray],
    starts: FloatArray,
    lo: FloatArray,
    hi: FloatArray,
    reach: HaltReachability | None,
    keeps_clear: Callable[[FloatArray], np.ndarray] | None = None,
) -> tuple[list[FloatArray], list[float], int]:
    """Maximise CP from each start (m, n) [rad] inside the box ``[lo, hi]``.

    ``cp_of(qs)`` gives CP (k,) of configurations (k, n) on the frozen scale.
    A refined point that leaves the reachable set (``reach``) is pulled back along the segment
    from its start (reachable; the set is convex).  With ``keeps_clear`` (configurations
    (k, n) -> (k,) bool, the clearance constraint, whose set is not convex) a refined point is
    pulled back to the last point of its straight path from the start that keeps clear.

    Returns
    -------
    refined_q, refined_cp
        One (n,) configuration [rad] and its CP per start.
    evaluations
        Configurations evaluated.
    """
    from scipy.optimize import minimize

    n = lo.size
    evaluations = 0
    steps = REFINE_FD_STEP * np.vstack([np.zeros(n), np.eye(n), -np.eye(n)])  # (2n+1, n)

    def fun(x: FloatArray) -> tuple[float, FloatArray]:
        nonlocal evaluations
        pts = np.clip(x + steps, lo, hi)
        val = cp_of(pts)
        evaluations += pts.shape[0]
        h = np.diagonal(pts[1 : n + 1]) - np.diagonal(pts[n + 1 :])  # per-joint step
        grad = np.divide(val[1 : n + 1] - val[n + 1 :], h, out=np.zeros(n), where=h > 0)
        return -float(val[0]), -grad

    refined_q: list[FloatArray] = []
    refined_cp: list[float] = []
    for start in starts:
        res = minimize(fun, start, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi)))
        x = np.clip(res.x, lo, hi)
        if reach is not None and not reach.contains(x):
            x = _pull_back(reach, start, x)
            evaluations += 1
        if keeps_clear is not None:
            x = _pull_back_clear(keeps_clear, start, x)
        refined_q.append(x)
        refined_cp.append(float(cp_of(x)))
    return refined_q, refined_cp, evaluations


def _pull_back_clear(keeps_clear: Callable[[FloatArray], np.ndarray], start: FloatArray, x: FloatArray) -> FloatArray:
    """The last point before the first that does not keep clear on the segment from ``start``
    (clear) to ``x``, checked at 257 points in one batched call (``x`` itself when all are)."""
    lam = np.linspace(0.0, 1.0, 257)
    ok = keeps_clear(start + lam[:, None] * (x - start))
    if ok.all():
        return x
    first_bad = int(np.argmin(ok))
    return start + lam[max(first_bad - 1, 0)] * (x - start)


def _pull_back(reach: HaltReachability, start: FloatArray, x: FloatArray, rounds: int = 3) -> FloatArray:
    """The farthest reachable point on the segment from ``start`` (reachable) to ``x``: the
    reachable set is convex, so its part of the segment is ``[0, lam*]``; each round checks 65
    points of the current bracket in one batched call."""
    a, b = 0.0, 1.0
    for _ in range(rounds):
        lam = np.linspace(a, b, 65)
        ok = reach.contains(start + lam[:, None] * (x - start))
        i = int(np.nonzero(ok)[0].max()) if ok.any() else 0
        a, b = float(lam[i]), float(lam[min(i + 1, lam.size - 1)])
    return start + a * (x - start)
