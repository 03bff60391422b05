"""Feasible ``k`` for a batch of halt configurations (the halt-configuration search's
check): :class:`AffineKBounds`, :class:`KIntervalBatch`, :func:`feasible_k_interval_batch`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._search1d import bisect_boundary
from ...errors import ScenarioError
from ...model import FloatArray
from ._feasibility import _slack
from ._polynomial import halt_coefficients, k_shape, polynomial_profile
from ._problem import HaltProblem, _vec

# -- feasible k for a batch of halt configurations -------------------------------------------
#
# For a fixed state at failure, T and limits, the halt's angle, rate and acceleration at time
# t are affine in the displacement h = qf - q0 of each joint *and* in k:
#
#     y_m(t) = A_m(t) + B_m(t) h + k phi_m(t)        (m = angle, rate, acceleration)
#
# (A: the quintic from (q0, dq0, ddq0) to rest at q0; B: the quintic's response to a unit
# displacement, 10 s^3 - 15 s^4 + 6 s^5 with s = t / T, and its derivatives).  Each limit at
# each grid time therefore bounds k by a line in h, and a joint's feasible k interval is
# [max of lines, min of lines]: the upper envelope of the lower-bound lines (convex,
# piecewise linear in h) and the lower envelope of the upper-bound lines (concave).  The
# envelopes are built once per (state, T, limits); evaluating them for K candidates is a
# binary search each, exact on the grid.  Times where phi_m(t) = 0 (t = 0, T; t = T / 2 for
# the rate) do not depend on k and bound h directly.
#
# Consequences used by the halt-configuration search: the configurations with a feasible
# shared k form a convex set, and joints couple only through the common k (for a given k each
# joint needs its own h_j with kmin_j(h_j) <= k <= kmax_j(h_j)).


@dataclass(frozen=True)
class KIntervalBatch:
    """Feasible ``k`` of a batch of halt configurations (:func:`feasible_k_interval_batch`).

    Attributes
    ----------
    joint
        (K, n, 2) feasible ``[k_min, k_max]`` of each joint's own ``k`` [rad/s^6]
        (``k_min > k_max``: empty), as :func:`feasible_k_intervals` per candidate.
    lower, upper
        (K,) feasible interval of one shared ``k`` [rad/s^6], as :func:`shared_k_interval`.
    feasible
        (K,) a shared ``k`` exists (000's halt: ``lower <= upper``).
    joint_feasible
        (K,) one ``k`` per joint exists (every joint's interval is non-empty).
    """

    joint: FloatArray
    lower: FloatArray
    upper: FloatArray
    feasible: np.ndarray
    joint_feasible: np.ndarray

    @classmethod
    def from_joint(cls, joint: FloatArray) -> KIntervalBatch:
        lower, upper = joint[..., 0].max(axis=-1), joint[..., 1].min(axis=-1)
        ok = np.all(joint[..., 0] <= joint[..., 1], axis=-1)
        return cls(joint, lower, upper, lower <= upper, ok)

    def mask(self, per_joint: bool = False) -> np.ndarray:
        """(K,) bool: feasible for a shared ``k`` (default) or one ``k`` per joint."""
        return self.joint_feasible if per_joint else self.feasible


def _upper_envelope(alpha: FloatArray, beta: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Upper envelope ``max_i alpha_i + beta_i h`` of lines: the lines that appear, in
    increasing slope, and the breakpoints between them (monotone convex-hull trick)."""
    order = np.lexsort((alpha, beta))
    a, b = alpha[order], beta[order]
    last = np.r_[b[1:] != b[:-1], True]  # equal slopes: the largest intercept only
    ha: list[float] = []
    hb: list[float] = []
    for ai, bi in zip(a[last].tolist(), b[last].tolist()):
        while len(ha) >= 2 and (ha[-2] - ai) * (hb[-1] - hb[-2]) <= (ha[-2] - ha[-1]) * (bi - hb[-2]):
            ha.pop()
            hb.pop()
        ha.append(ai)
        hb.append(bi)
    ea, eb = np.array(ha), np.array(hb)
    return ea, eb, (ea[:-1] - ea[1:]) / (eb[1:] - eb[:-1])


def _eval_envelope(env: tuple[FloatArray, FloatArray, FloatArray], h: FloatArray) -> FloatArray:
    a, b, x = env
    i = np.searchsorted(x, h)
    best = np.full(h.shape, -np.inf)
    for d in (-1, 0, 1):  # the neighbours too: robust to round-off in the breakpoints
        j = np.clip(i + d, 0, a.size - 1)
        best = np.maximum(best, a[j] + b[j] * h)
    return best


class AffineKBounds:
    """The halt's limits as bounds on ``k`` that are affine in the halt configuration.

    Built once for a state at failure ``(q0, dq0, ddq0)``, a halt time ``T``, the limits and
    the check grid (the same ``n_check``-point grid as :class:`HaltProblem`); then
    :meth:`intervals` gives the feasible ``k`` of any batch of halt configurations, exactly
    on the grid, without a loop over candidates.

    Parameters
    ----------
    q0, dq0, ddq0
        (n,) state at failure [rad, rad/s, rad/s^2].
    T
        Halt time [s].
    dq_max, ddq_max
        (n,) or scalar speed and acceleration limits [rad/s, rad/s^2].
    q_min, q_max
        (n,) angle limits [rad]; None: no angle limit.
    n_check
        Grid points of the check (as ``HaltProblem.n_check``).
    """

    def __init__(
        self,
        q0: ArrayLike,
        dq0: ArrayLike,
        ddq0: ArrayLike,
        T: float,
        dq_max: ArrayLike,
        ddq_max: ArrayLike,
        q_min: ArrayLike | None = None,
        q_max: ArrayLike | None = None,
        *,
        n_check: int = 2001,
    ) -> None:
        q0 = np.asarray(q0, dtype=float)
        if q0.ndim != 1:
            raise ScenarioError(f"q0 must be a vector (n,) [rad]; got shape {q0.shape}")
        n = q0.size
        self.q0 = _vec(q0, n, "q0", "rad")
        self.dq0 = _vec(dq0, n, "dq0", "rad/s")
        self.ddq0 = _vec(ddq0, n, "ddq0", "rad/s^2")
        self.dq_max = _vec(dq_max, n, "dq_max", "rad/s", positive=True)
        self.ddq_max = _vec(ddq_max, n, "ddq_max", "rad/s^2", positive=True)
        lo_q = np.full(n, -np.inf) if q_min is None else np.broadcast_to(np.asarray(q_min, float), (n,))
        hi_q = np.full(n, np.inf) if q_max is None else np.broadcast_to(np.asarray(q_max, float), (n,))
        T = float(T)
        if not (math.isfinite(T) and T > 0):
            raise ScenarioError(f"halt time T must be a finite number > 0 [s]; got {T}")
        if int(n_check) < 3:
            raise ScenarioError(f"n_check must be >= 3; got {n_check}")
        self.T, self.n_check, self.dof = T, int(n_check), n
        t = np.linspace(0.0, T, self.n_check)
        A = np.stack(polynomial_profile(halt_coefficients(q0, self.dq0, self.ddq0, q0, T, 0.0), t))
        B = np.stack(polynomial_profile(halt_coefficients(0.0, 0.0, 0.0, 1.0, T, 0.0)[None], t))[..., 0]
        phi = np.stack(k_shape(t, T))  # (3, n_t)
        lo = np.stack([lo_q, -self.dq_max, -self.ddq_max])  # (3, n)
        hi = np.stack([hi_q, self.dq_max, self.ddq_max])
        sl = _slack(np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0))
        self._A, self._B, self._phi, self._lo, self._hi = A, B, phi, lo, hi  # (3,n_t,n), (3,n_t) x2, (3,n) x2
        self.q_min, self.q_max = lo_q.copy(), hi_q.copy()
        # where phi_m(t) = 0 the value A + B h does not depend on k: an interval of h per joint
        fix_lo, fix_hi = np.full(n, -np.inf), np.full(n, np.inf)
        lo_s, hi_s = lo - sl, hi + sl
        for m, i in zip(*np.nonzero(phi == 0)):
            a, b = A[m, i], B[m, i]
            if b == 0:
                bad = (a < lo_s[m]) | (a > hi_s[m])
                fix_lo[bad], fix_hi[bad] = np.inf, -np.inf
            else:
                with np.errstate(invalid="ignore"):
                    e1, e2 = (lo_s[m] - a) / b, (hi_s[m] - a) / b
                fix_lo = np.maximum(fix_lo, np.fmin(e1, e2))
                fix_hi = np.minimum(fix_hi, np.fmax(e1, e2))
        self._fix = (fix_lo, fix_hi)
        nz = phi != 0
        ph = phi[nz]
        beta = -B[nz] / ph
        self._kmin_env, self._kmax_env = [], []
        for j in range(n):
            a_lo = (np.broadcast_to(lo[:, j, None], phi.shape)[nz] - A[:, :, j][nz]) / ph
            a_hi = (np.broadcast_to(hi[:, j, None], phi.shape)[nz] - A[:, :, j][nz]) / ph
            kmin_a = np.where(ph > 0, a_lo, a_hi)
            kmax_a = np.where(ph > 0, a_hi, a_lo)
            fin = np.isfinite(kmin_a)
            self._kmin_env.append(_upper_envelope(kmin_a[fin], beta[fin]))
            fin = np.isfinite(kmax_a)
            self._kmax_env.append(_upper_envelope(-kmax_a[fin], -beta[fin]))  # min = -max(-.)

    @classmethod
    def from_problem(cls, problem: HaltProblem) -> AffineKBounds:
        """The bounds of a :class:`HaltProblem`'s state, ``T``, limits and check grid."""
        p = problem
        return cls(p.q0, p.dq0, p.ddq0, p.T, p.dq_max, p.ddq_max, p.q_min, p.q_max, n_check=p.n_check)

    def joint_intervals(self, h: ArrayLike) -> FloatArray:
        """(..., n, 2) feasible ``[k_min, k_max]`` of each joint [rad/s^6] for displacements
        ``h = qf - q0`` (..., n) [rad]."""
        h = np.asarray(h, dtype=float)
        if h.shape[-1:] != (self.dof,):
            raise ScenarioError(f"halt configurations must have shape (..., {self.dof}); got {h.shape}")
        out = np.empty(h.shape + (2,))
        fix_lo, fix_hi = self._fix
        for j in range(self.dof):  # a loop over joints, not candidates
            hj = h[..., j]
            kmin = _eval_envelope(self._kmin_env[j], hj)
            kmax = -_eval_envelope(self._kmax_env[j], hj)
            out_fix = (hj < fix_lo[j]) | (hj > fix_hi[j])
            out[..., j, 0] = np.where(out_fix, np.inf, kmin)
            out[..., j, 1] = np.where(out_fix, -np.inf, kmax)
        return out

    def intervals(self, qf: ArrayLike) -> KIntervalBatch:
        """Feasible ``k`` of halt configurations ``qf`` (K, n) [rad] (or (n,))."""
        return KIntervalBatch.from_joint(self.joint_intervals(np.asarray(qf, dtype=float) - self.q0))

    def dense_intervals(self, qf: ArrayLike, *, chunk_elements: int = 4_000_000) -> KIntervalBatch:
        """Same as :meth:`intervals`, by brute force: every (candidate, limit, time, joint)
        bound evaluated as :func:`feasible_k_intervals` does, in chunks of candidates."""
        h = np.atleast_2d(np.asarray(qf, dtype=float) - self.q0)
        shape = h.shape[:-1]
        h = h.reshape(-1, self.dof)
        phi = self._phi[:, :, None]
        nz = np.abs(phi) > 0
        safe = np.where(nz, phi, 1.0)
        lo, hi = self._lo[:, None, :], self._hi[:, None, :]
        sl = _slack(
            np.where(np.isfinite(self._lo), self._lo, 0.0), np.where(np.isfinite(self._hi), self._hi, 0.0)
        )
        lo_s, hi_s = lo - sl[:, None, :], hi + sl[:, None, :]
        step = max(1, chunk_elements // (3 * self.n_check * self.dof))
        out = np.empty((h.shape[0], self.dof, 2))
        for s0 in range(0, h.shape[0], step):  # chunks of candidates, each one batched computation
            base = self._A[None] + self._B[None, :, :, None] * h[s0 : s0 + step, None, None, :]
            with np.errstate(invalid="ignore"):
                b1, b2 = (lo - base) / safe, (hi - base) / safe
            kmin = np.where(nz & np.isfinite(b1 + b2), np.fmin(b1, b2), -np.inf)
            kmax = np.where(nz & np.isfinite(b1 + b2), np.fmax(b1, b2), np.inf)
            bad = (~nz) & ((base < lo_s) | (base > hi_s))
            out[s0 : s0 + step, :, 0] = np.where(bad, np.inf, kmin).max(axis=(1, 2))
            out[s0 : s0 + step, :, 1] = np.where(bad, -np.inf, kmax).min(axis=(1, 2))
        return KIntervalBatch.from_joint(out.reshape(shape + (self.dof, 2)))

    def configuration_box(
        self,
        lower: ArrayLike,
        upper: ArrayLike,
        *,
        per_joint: bool = False,
        n_grid: int = 4001,
        bisections: int = 50,
    ) -> tuple[FloatArray, FloatArray, tuple[float, float] | None, FloatArray] | None:
        """Bounding box of the halt configurations in ``[lower, upper]`` that have a feasible
        ``k``: the exact projection of the feasible set on each joint, to the resolution of an
        ``n_grid``-point grid per joint (edges refined by bisection).

        For a shared ``k`` the feasible ``k`` of the whole set is the intersection over joints
        of ``K_j = {k: some h_j has kmin_j(h_j) <= k <= kmax_j(h_j)}``; a joint's projection
        is where its interval meets that intersection.  With ``per_joint`` the feasible set
        *is* the box.

        Returns
        -------
        ``(lower, upper, k_range, witness)`` -- the box [rad], the feasible shared ``k`` of
        the set [rad/s^6] (None with ``per_joint``) and one feasible configuration -- or None
        when no configuration in the box has a feasible ``k`` (on the grid).
        """
        lo_h = np.asarray(lower, dtype=float) - self.q0
        hi_h = np.asarray(upper, dtype=float) - self.q0
        if np.any(hi_h < lo_h):
            return None
        H = lo_h + (hi_h - lo_h) * np.linspace(0.0, 1.0, int(n_grid))[:, None]  # (G, n)
        J = self.joint_intervals(H)
        ok = J[..., 0] <= J[..., 1]
        if not np.all(ok.any(axis=0)):
            return None
        k_range = None
        if per_joint:
            member = ok
        else:
            kl = float(np.where(ok, J[..., 0], np.inf).min(axis=0).max())
            ku = float(np.where(ok, J[..., 1], -np.inf).max(axis=0).min())
            if not kl <= ku:
                return None
            k_range = (kl, ku)
            member = ok & (J[..., 0] <= ku) & (J[..., 1] >= kl)

        def inside(h: FloatArray) -> np.ndarray:
            Jh = self.joint_intervals(h)
            m = Jh[..., 0] <= Jh[..., 1]
            if k_range is not None:
                m &= (Jh[..., 0] <= k_range[1]) & (Jh[..., 1] >= k_range[0])
            return m

        cols = np.arange(self.dof)
        first = np.argmax(member, axis=0)
        last = member.shape[0] - 1 - np.argmax(member[::-1], axis=0)
        # bisection of both edges of every joint at once: rows (low edge, high edge)
        a = np.stack([H[np.maximum(first - 1, 0), cols], H[np.minimum(last + 1, H.shape[0] - 1), cols]])
        b = np.stack([H[first, cols], H[last, cols]])  # inside
        b = bisect_boundary(inside, a, b, iterations=max(int(bisections), 0)).true_end
        witness_h = H[first, cols]
        if k_range is not None:  # one h per joint whose interval holds a common k
            kc = 0.5 * (k_range[0] + k_range[1])
            good = (J[..., 0] <= kc) & (J[..., 1] >= kc) & ok
            if np.all(good.any(axis=0)):
                witness_h = H[np.argmax(good, axis=0), cols]
        return self.q0 + b[0], self.q0 + b[1], k_range, self.q0 + witness_h


def feasible_k_interval_batch(
    q0: ArrayLike,
    dq0: ArrayLike,
    ddq0: ArrayLike,
    qf: ArrayLike,
    T: float,
    dq_max: ArrayLike,
    ddq_max: ArrayLike,
    q_min: ArrayLike | None = None,
    q_max: ArrayLike | None = None,
    *,
    n_check: int = 2001,
    method: Literal["envelope", "dense"] = "envelope",
) -> KIntervalBatch:
    """Feasible ``k`` of the halt to each of K candidate halt configurations, in one batched
    computation (no loop over candidates).

    Every limit at every time of the ``n_check``-point grid is affine in ``k``, so each
    candidate's feasible set is an exact interval per joint (intersected over the joints for
    000's shared ``k``): the same numbers as :func:`feasible_k_intervals` /
    :func:`shared_k_interval` of a :class:`HaltProblem` per candidate.

    Parameters
    ----------
    q0, dq0, ddq0
        (n,) state at failure [rad, rad/s, rad/s^2].
    qf
        (K, n) (or (..., n)) candidate halt configurations [rad].
    T
        Halt time [s].
    dq_max, ddq_max
        Speed and acceleration limits, scalar or (n,) [rad/s, rad/s^2].
    q_min, q_max
        (n,) angle limits [rad]; None: none.
    n_check
        Time grid of the check (as ``HaltProblem.n_check``).
    method
        ``"envelope"`` (default): the bounds from all grid times are lines in
        ``h = qf - q0``; their upper/lower envelopes are built once and evaluated for every
        candidate by binary search (O(K log n_check)).  ``"dense"``: every bound of every
        candidate, in chunks (O(K n_check), a reference).

    Returns
    -------
    KIntervalBatch
        ``joint`` (K, n, 2), ``lower``/``upper``/``feasible`` (K,) for a shared ``k``,
        ``joint_feasible`` (K,) for one ``k`` per joint.
    """
    bounds = AffineKBounds(q0, dq0, ddq0, T, dq_max, ddq_max, q_min, q_max, n_check=n_check)
    if method == "envelope":
        return bounds.intervals(qf)
    if method == "dense":
        return bounds.dense_intervals(qf)
    raise ScenarioError(f"method must be 'envelope' or 'dense'; got {method!r}")
