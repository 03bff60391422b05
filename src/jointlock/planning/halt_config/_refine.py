"""Beyond 000: the bounded local refinement of the best samples (L-BFGS-B on CP with its
normalisation and weights frozen, central-difference gradients in one batched call), keeping
the reachability constraint."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...model import FloatArray
from ._lockstep import lockstep_available, minimize_lockstep
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
    *,
    lockstep: bool = False,
) -> tuple[list[FloatArray], list[float], int]:
    """Maximise CP from each start (m, n) [rad] inside the box ``[lo, hi]``.

    ``cp_of(qs)`` gives CP (k,) of configurations (k, n) on the frozen scale.  ``lockstep``:
    the starts run together, each step's evaluations in one call of ``cp_of``
    (:func:`~._lockstep.minimize_lockstep`; the same points as one ``minimize`` per start,
    bit for bit, where ``cp_of`` gives a configuration the CP it gives it alone: the
    compiled kernel's), where this scipy allows it and the box has no fixed joint.
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

    def evaluate(xs: FloatArray) -> tuple[FloatArray, FloatArray]:
        """-CP (k,) and its central-difference gradient (k, n) at the points ``xs`` (k, n), from
        each point's 2n+1 points (the point, then +h and -h along each joint, clipped), in one
        call of ``cp_of``."""
        nonlocal evaluations
        pts = np.clip(xs[:, None, :] + steps, lo, hi)  # (k, 2n+1, n)
        evaluations += pts.shape[0] * pts.shape[1]
        val = cp_of(pts.reshape(-1, n)).reshape(pts.shape[:2])
        h = np.diagonal(pts[:, 1 : n + 1], axis1=1, axis2=2) - np.diagonal(pts[:, n + 1 :], axis1=1, axis2=2)
        grad = np.divide(val[:, 1 : n + 1] - val[:, n + 1 :], h, out=np.zeros(h.shape), where=h > 0)
        return -val[:, 0], -grad

    def fun(x: FloatArray) -> tuple[float, FloatArray]:  # one point, as minimize asks
        value, grad = evaluate(x[None])
        return float(value[0]), grad[0]

    if lockstep and _lockstep_box(starts, lo, hi):
        finals = list(minimize_lockstep(evaluate, starts, lo, hi))
    else:
        finals = [minimize(fun, start, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi))).x for start in starts]
    refined_q: list[FloatArray] = []
    refined_cp: list[float] = []
    for start, final in zip(starts, finals):
        x = np.clip(final, lo, hi)
        if reach is not None and not reach.contains(x):
            x = _pull_back(reach, start, x)
            evaluations += 1
        if keeps_clear is not None:
            x = _pull_back_clear(keeps_clear, start, x)
        refined_q.append(x)
        refined_cp.append(float(cp_of(x)))
    return refined_q, refined_cp, evaluations


def _lockstep_box(starts: FloatArray, lo: FloatArray, hi: FloatArray) -> bool:
    """Whether the starts can run in lockstep: this scipy allows it, the box is finite with no
    fixed joint, and every angle in it is below the kernels' ``TRIG_LIMIT`` (beyond, a block
    of 128 configurations takes libm's sine and cosine for all its lanes when one angle gets
    there, and a configuration's CP would depend on the batch it is in)."""
    from ..._kernels import TRIG_LIMIT  # the lockstep runs compiled: numba is loaded

    box = np.array([lo, hi])
    return bool(
        starts.shape[0] and lockstep_available() and np.all(lo < hi) and np.all(np.abs(box) < TRIG_LIMIT)
    )


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
