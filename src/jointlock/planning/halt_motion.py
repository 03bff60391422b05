"""Optimal halt motion (seed 000 §4): the 6th-order halt polynomial with one free
coefficient ``k``, the joint-limit check, the global base disturbance torque, and solvers.

Method (000 eqs. 25-38)
-----------------------
Every healthy joint moves from the state at failure ``(q0, dq0, ddq0)`` to the halt
configuration ``qf`` at rest (``dqf = ddqf = 0``) in the halt time ``T`` along

    q(t) = a0 + a1 t + ... + a6 t^6,   a6 = k                       (eqs. 25-27)

The ``k``-part of eq. 27 is ``k t^3 (t - T)^3``: a triple root at both ends, so it leaves
all six boundary conditions untouched and ``q(t; k) = q_quintic(t) + k t^3 (t - T)^3``.
Its extremum, at ``t = T/2``, is ``-k T^6 / 64`` (``t^3 (t - T)^3 <= 0`` on ``[0, T]``).

The objective is the time average of the 2-norm of the base disturbance torque (eq. 32),
``tau_bar(k) = 1/T int_0^T ||n_d(t; k)|| dt`` with ``n_d`` from :func:`jointlock.dynamics.rnea`
(000 eqs. 28-31; base held fixed as in 000, or free-floating), integrated by Simpson's
rule.  Constraints (eq. 33): angle, speed and acceleration limits per joint on a dense
time grid.  Each constraint is affine in ``k``, so the feasible set of a shared ``k`` is an
interval computed exactly on the grid (and a box for one ``k`` per joint).

Units of ``k``
--------------
Inside the library ``k`` is in rad/s^6 (SI).  000 works in degrees: its ``k = 0.0018``
reads as deg/s^6 (a 28 deg swing at mid-halt for ``T = 10`` s; in rad/s^6 it would be a
28 rad swing, far outside every limit), so the paper's reading is **deg/s^6**:
``k_si = k_paper * pi / 180`` (:data:`K_UNIT_SCALE`).  The CLI reports ``k`` in deg/s^6.

Infeasible scenarios are reported, never optimised silently: :class:`HaltMotion` then
has ``feasible=False``, the least-violating ``k``, the violations (joint, limit, excess)
and the smallest halt time ``T`` for which a feasible ``k`` exists.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize, minimize_scalar

from ..dynamics import BaseMode, rnea
from ..errors import InfeasibleError, ScenarioError
from ..model import ArmModel, FloatArray
from .ga import GAResult, GASettings, adaptive_ga, bits_for_precision

log = logging.getLogger(__name__)

#: Factor from the unit of ``k`` to rad/s^6: 000's reading is deg/s^6.
K_UNIT_SCALE: dict[str, float] = {"deg/s^6": math.pi / 180.0, "rad/s^6": 1.0}
#: Slack on every limit when checking feasibility (relative to the limit) [-]: round-off only.
LIMIT_RTOL = 1e-9
#: Samples below which Simpson's rule on the halt is refused.
MIN_SAMPLES = 11
#: Largest number of (candidate, time) samples passed to one :func:`rnea` call.
CHUNK_SAMPLES = 60_000
#: Floor of the global torque in the GA's fitness ``1 / tau_bar`` (eq. 35) [N m]: a halt
#: without base torque scores ``1e300``, finite, and a population's sum stays finite too.
TORQUE_FLOOR = 1e-300

Solver = Literal["scan", "ga", "vector"]
LimitKind = Literal["angle", "velocity", "acceleration"]


# -- the halt polynomial (eqs. 25-27) -------------------------------------------------------


def halt_coefficients(
    q0: ArrayLike,
    dq0: ArrayLike,
    ddq0: ArrayLike,
    qf: ArrayLike,
    T: float,
    k: ArrayLike,
    dqf: ArrayLike = 0.0,
    ddqf: ArrayLike = 0.0,
) -> FloatArray:
    """Coefficients ``a0..a6`` of 000 eq. 27 for every joint.

    Parameters
    ----------
    q0, dq0, ddq0
        (..., n) state at failure [rad, rad/s, rad/s^2].
    qf, dqf, ddqf
        (..., n) final state [rad, rad/s, rad/s^2] (000: at rest).
    T
        Halt time ``t_f - t_0`` [s], > 0.
    k
        (...) or (..., n) free coefficient ``a6`` [rad/s^6] (broadcast against the joints).

    Returns
    -------
    (..., n, 7) coefficients ``a0 .. a6`` in SI units (``a_j`` in rad/s^j).
    """
    q0, dq0, ddq0, qf, dqf, ddqf, k = (np.asarray(x, dtype=float) for x in (q0, dq0, ddq0, qf, dqf, ddqf, k))
    names = ("q0", "dq0", "ddq0", "qf", "dqf", "ddqf", "k")
    shapes = [x.shape for x in (q0, dq0, ddq0, qf, dqf, ddqf, k)]
    try:
        np.broadcast_shapes(*shapes)
    except ValueError:
        got = ", ".join(f"{n} {sh}" for n, sh in zip(names, shapes))
        raise ScenarioError(
            f"halt_coefficients: the states must broadcast to one shape (..., n) and k against them "
            f"((...) with a trailing 1, or (..., n)); got {got}"
        ) from None
    T = float(T)
    if not T > 0:
        raise ScenarioError(f"halt time T must be > 0 [s]; got {T}")
    h = qf - q0
    a3 = -(T**3) * k + (20 * h - T**2 * (3 * ddq0 - ddqf) - T * (8 * dqf + 12 * dq0)) / (2 * T**3)
    a4 = 3 * T**2 * k + (T**2 * (3 * ddq0 - 2 * ddqf) + T * (14 * dqf + 16 * dq0) - 30 * h) / (2 * T**4)
    a5 = -3 * T * k + ((ddqf - ddq0) * T**2 - 6 * (dq0 + dqf) * T + 12 * h) / (2 * T**5)
    parts = np.broadcast_arrays(q0, dq0, ddq0 / 2, a3, a4, a5, k + 0 * h)
    return np.stack(parts, axis=-1)


def polynomial_profile(coefficients: ArrayLike, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Angle, rate and acceleration of eq. 25 at times ``t``.

    Parameters
    ----------
    coefficients
        (..., n, 7) from :func:`halt_coefficients`.
    t
        (n_t,) times since the failure [s].

    Returns
    -------
    q, dq, ddq
        each (..., n_t, n) [rad, rad/s, rad/s^2].
    """
    c = np.asarray(coefficients, dtype=float)
    t = np.asarray(t, dtype=float)
    powers = t[:, None] ** np.arange(7)  # (n_t, 7)
    j = np.arange(7)
    d1 = np.zeros_like(powers)
    d1[:, 1:] = j[1:] * powers[:, :-1]
    d2 = np.zeros_like(powers)
    d2[:, 2:] = j[2:] * (j[2:] - 1) * powers[:, :-2]
    return tuple(np.einsum("...jc,tc->...tj", c, p) for p in (powers, d1, d2))  # type: ignore[return-value]


def k_shape(t: ArrayLike, T: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The ``k``-part of eq. 27, ``phi(t) = t^3 (t - T)^3``, and its first two derivatives,
    each (n_t,) [s^6, s^5, s^4]."""
    t = np.asarray(t, dtype=float)
    u = t - T
    phi = t**3 * u**3
    dphi = 3 * t**2 * u**2 * (t + u)
    ddphi = 6 * t * u * (t**2 + 3 * t * u + u**2)
    return phi, dphi, ddphi


# -- the problem --------------------------------------------------------------------------


def _angle_limit(value: ArrayLike, n: int, name: str) -> FloatArray:
    """Angle limits (n,) [rad]: finite, or -inf/+inf for a joint without a limit (a continuous
    joint: its angle constraint is absent); NaN is refused."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or np.any(np.isnan(arr)):
        raise ScenarioError(
            f"{name} must be one value or {n} values [rad], -inf/+inf for no limit, not NaN; "
            f"got {arr.tolist()}"
        )
    out = arr.copy()
    out.setflags(write=False)
    return out


def _vec(value: ArrayLike, n: int, name: str, unit: str, *, positive: bool = False) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{name} must be one finite value or {n} values [{unit}]; got {arr.tolist()}")
    if positive and not np.all(arr > 0):
        raise ScenarioError(f"{name} must be > 0 [{unit}]; got {arr.tolist()}")
    out = arr.copy()
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class HaltProblem:
    """A halt-motion problem (000 eq. 34), in SI units and radians.

    Attributes
    ----------
    model
        The locked arm (healthy joints only); for ``base="floating"`` it must carry a spacecraft.
    q0, dq0, ddq0
        (n,) state at failure [rad, rad/s, rad/s^2].
    qf
        (n,) halt configuration [rad] (000: ``q_best``).
    T
        Halt time [s].
    dq_max, ddq_max
        (n,) speed and acceleration limits [rad/s, rad/s^2] (symmetric).
    q_min, q_max
        (n,) angle limits [rad]; default the model's.  ``-inf``/``+inf`` (a continuous
        joint): no angle constraint for that joint.
    base
        ``"fixed"`` (000) or ``"floating"`` base for the disturbance torque.
    n_samples
        Time samples of the objective (odd; Simpson's rule).
    n_check
        Time samples of the constraint check.
    """

    model: ArmModel
    q0: FloatArray
    dq0: FloatArray
    ddq0: FloatArray
    qf: FloatArray
    T: float
    dq_max: FloatArray
    ddq_max: FloatArray
    q_min: FloatArray | None = None
    q_max: FloatArray | None = None
    base: BaseMode = "fixed"
    n_samples: int = 501
    n_check: int = 2001

    def __post_init__(self) -> None:
        n = self.model.dof
        for name, unit in (("q0", "rad"), ("dq0", "rad/s"), ("ddq0", "rad/s^2"), ("qf", "rad")):
            object.__setattr__(self, name, _vec(getattr(self, name), n, name, unit))
        object.__setattr__(self, "dq_max", _vec(self.dq_max, n, "dq_max", "rad/s", positive=True))
        object.__setattr__(self, "ddq_max", _vec(self.ddq_max, n, "ddq_max", "rad/s^2", positive=True))
        lo = self.model.lower if self.q_min is None else self.q_min
        hi = self.model.upper if self.q_max is None else self.q_max
        lo, hi = _angle_limit(lo, n, "q_min"), _angle_limit(hi, n, "q_max")
        if np.any(lo > hi):
            raise ScenarioError(f"q_min must be <= q_max [rad]; got {lo.tolist()} and {hi.tolist()}")
        object.__setattr__(self, "q_min", lo)
        object.__setattr__(self, "q_max", hi)
        T = float(self.T)
        if not (math.isfinite(T) and T > 0):
            raise ScenarioError(f"halt time T must be a finite number > 0 [s]; got {self.T}")
        object.__setattr__(self, "T", T)
        if self.base not in ("fixed", "floating"):
            raise ScenarioError(f"base must be 'fixed' or 'floating'; got {self.base!r}")
        if self.base == "floating" and not self.model.floating:
            raise ScenarioError(
                "base='floating' needs a model with a spacecraft (load it with base='floating')"
            )
        for name in ("n_samples", "n_check"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
                raise ScenarioError(f"{name} must be an integer; got {v!r}")
        if self.n_samples < MIN_SAMPLES or self.n_samples % 2 == 0:
            raise ScenarioError(f"n_samples must be odd and >= {MIN_SAMPLES}; got {self.n_samples}")
        if self.n_check < 3:
            raise ScenarioError(f"n_check must be >= 3; got {self.n_check}")

    @property
    def dof(self) -> int:
        return self.model.dof

    def with_time(self, T: float) -> HaltProblem:
        """The same problem with another halt time [s]."""
        return replace(self, T=T)

    def times(self, n: int | None = None) -> FloatArray:
        """(n,) uniform time grid on [0, T] [s] (``n_samples`` points by default)."""
        return np.linspace(0.0, self.T, self.n_samples if n is None else n)

    def base_profile(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The ``k = 0`` (quintic) part: q, dq, ddq each (n_t, n)."""
        coef = halt_coefficients(self.q0, self.dq0, self.ddq0, self.qf, self.T, 0.0)
        return polynomial_profile(coef, t)

    def k_shape(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``phi(t) = t^3 (t - T)^3`` and its first two derivatives, each (n_t,) [s^6, s^5, s^4]."""
        return k_shape(t, self.T)

    def trajectory(
        self, k: ArrayLike, t: ArrayLike | None = None, *, per_joint: bool = False
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint angles, rates and accelerations of the halt for one or many ``k``.

        Parameters
        ----------
        k
            [rad/s^6]: shape (...) for one shared ``k`` per candidate (000), or (..., n) with
            ``per_joint=True`` (one per joint).
        t
            (n_t,) times [s]; default :meth:`times`.

        Returns
        -------
        q, dq, ddq
            each (..., n_t, n) [rad, rad/s, rad/s^2].
        """
        t = self.times() if t is None else np.asarray(t, dtype=float)
        k = _k_array(k, self.dof, per_joint)
        base = self.base_profile(t)
        shape = self.k_shape(t)
        kk = k[..., None, :]
        return tuple(b + kk * s[:, None] for b, s in zip(base, shape))  # type: ignore[return-value]


def _k_array(k: ArrayLike, n: int, per_joint: bool) -> FloatArray:
    k = np.asarray(k, dtype=float)
    if per_joint:
        if k.ndim == 0 or k.shape[-1] != n:
            raise ScenarioError(f"per-joint k must have shape (..., {n}) [rad/s^6]; got {k.shape}")
        return k
    return np.broadcast_to(k[..., None], k.shape + (n,))


# -- objective (eq. 32) --------------------------------------------------------------------


def _simpson_mean(values: FloatArray, T: float) -> FloatArray:
    """Time average over the last axis of uniformly sampled values (odd count), Simpson's rule."""
    n = values.shape[-1]
    w = np.ones(n)
    w[1:-1:2] = 4.0
    w[2:-1:2] = 2.0
    return values @ w / (3.0 * (n - 1))


def base_torque_history(
    problem: HaltProblem, k: ArrayLike, t: ArrayLike | None = None, *, per_joint: bool = False
) -> FloatArray:
    """Base disturbance torque ``tau_b(t; k)`` (000 eq. 31), (..., n_t, 3) [N m], root frame."""
    q, dq, ddq = problem.trajectory(k, t, per_joint=per_joint)
    return rnea(problem.model, q, dq, ddq, base=problem.base).base_moment


def global_base_torque(problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False) -> FloatArray:
    """Global base disturbance torque of 000 eq. 32 for a batch of ``k``.

    ``tau_bar(k) = (1/T) int_0^T ||tau_b(t; k)||_2 dt``, Simpson's rule on
    ``problem.n_samples`` points.  Candidates are processed in chunks of at most
    :data:`CHUNK_SAMPLES` (candidate, time) samples, each chunk one batched :func:`rnea` call.

    Parameters
    ----------
    k
        (...) shared ``k`` [rad/s^6], or (..., n) with ``per_joint=True``.

    Returns
    -------
    (...) [N m].
    """
    k = np.asarray(k, dtype=float)
    if per_joint and (k.ndim == 0 or k.shape[-1] != problem.dof):
        raise ScenarioError(
            f"k with per_joint=True must have shape (..., {problem.dof}) (one k per healthy joint "
            f"{list(problem.model.joint_numbers)}) [rad/s^6]; got shape {k.shape}"
        )
    batch = k.shape[:-1] if per_joint else k.shape
    flat = k.reshape((-1, problem.dof) if per_joint else (-1,))
    t = problem.times()
    step = max(1, CHUNK_SAMPLES // t.size)
    out = np.empty(flat.shape[0])
    for start in range(0, flat.shape[0], step):  # chunks of candidates, not samples
        torque = base_torque_history(problem, flat[start : start + step], t, per_joint=per_joint)
        out[start : start + step] = _simpson_mean(np.linalg.norm(torque, axis=-1), problem.T)
    return out.reshape(batch)


# -- constraints (eq. 33) ------------------------------------------------------------------


@dataclass(frozen=True)
class Violation:
    """One violated limit: joint number (1-based), which limit, the limit, the worst value
    reached, by how much it is exceeded (same unit, > 0), and when [s].  Values in SI
    (rad, rad/s, rad/s^2)."""

    joint: int
    kind: LimitKind
    limit: float
    value: float
    excess: float
    time: float

    def describe(self) -> str:
        unit = {"angle": "deg", "velocity": "deg/s", "acceleration": "deg/s^2"}[self.kind]
        return (
            f"joint {self.joint} {self.kind} reaches {math.degrees(self.value):.3f} {unit} at "
            f"t = {self.time:.3f} s: limit {math.degrees(self.limit):.3f} {unit} exceeded by "
            f"{math.degrees(self.excess):.3f} {unit} ({100 * self.excess / abs(self.limit):.1f} %)"
        )


def _limits(problem: HaltProblem) -> tuple[FloatArray, FloatArray]:
    """(3, n) lower and upper limits for angle, velocity, acceleration."""
    lo = np.stack([problem.q_min, -problem.dq_max, -problem.ddq_max])
    hi = np.stack([problem.q_max, problem.dq_max, problem.ddq_max])
    return lo, hi


def _slack(lo: FloatArray, hi: FloatArray) -> FloatArray:
    """Round-off slack of each limit (relative to its finite ends; an infinite end -- no
    limit -- needs none)."""
    lo, hi = np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0)
    return LIMIT_RTOL * np.maximum(np.maximum(np.abs(lo), np.abs(hi)), 1.0)


def feasible_k_intervals(problem: HaltProblem) -> FloatArray:
    """Exact feasible interval of ``k`` for every joint on the check grid.

    Each limit at each time is affine in ``k`` (``g0(t) + k phi(t)``), so every joint's
    feasible set is an interval; for a shared ``k`` (000) intersect them
    (:func:`shared_k_interval`).

    Returns
    -------
    (n, 2) ``[k_min, k_max]`` per joint [rad/s^6]; ``k_min > k_max`` (or NaN-free
    ``+inf/-inf``) when empty.
    """
    t = problem.times(problem.n_check)
    base = np.stack(problem.base_profile(t))  # (3, n_t, n)
    shape = np.stack(problem.k_shape(t))[:, :, None]  # (3, n_t, 1)
    lo, hi = _limits(problem)
    sl = _slack(lo, hi)
    lo_s, hi_s = (lo - sl)[:, None, :], (hi + sl)[:, None, :]
    nz = np.abs(shape) > 0
    safe = np.where(nz, shape, 1.0)
    b1 = (lo[:, None, :] - base) / safe  # exact limits, so that k on a bound is within the slack
    b2 = (hi[:, None, :] - base) / safe
    kmin = np.where(nz, np.minimum(b1, b2), -np.inf)
    kmax = np.where(nz, np.maximum(b1, b2), np.inf)
    # where phi^(j)(t) = 0 the value does not depend on k: it must already be within limits
    fixed_bad = (~nz) & ((base < lo_s) | (base > hi_s))
    kmin = np.where(fixed_bad, np.inf, kmin)
    kmax = np.where(fixed_bad, -np.inf, kmax)
    return np.stack([kmin.max(axis=(0, 1)), kmax.min(axis=(0, 1))], axis=-1)


def shared_k_interval(problem: HaltProblem) -> tuple[float, float]:
    """Feasible interval of one shared ``k`` [rad/s^6]; empty when ``lo > hi``."""
    per = feasible_k_intervals(problem)
    return float(per[:, 0].max()), float(per[:, 1].min())


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
        for _ in range(int(bisections)):
            mid = 0.5 * (a + b)
            m = inside(mid)
            a, b = np.where(m, a, mid), np.where(m, mid, b)
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


def relative_violation(problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False) -> FloatArray:
    """Largest limit excess relative to its limit (0 when feasible), for a batch of ``k``:
    (...) [-]; a number per candidate, max over joints, limits and the check grid."""
    t = problem.times(problem.n_check)
    lo, hi = _limits(problem)
    traj = np.stack(problem.trajectory(k, t, per_joint=per_joint), axis=-3)  # (..., 3, n_t, n)
    scale = np.maximum(np.abs(lo), np.abs(hi))
    scale = np.where(np.isfinite(scale), scale, 1.0)[:, None, :]  # no angle limit: never exceeded
    excess = np.maximum(traj - hi[:, None, :], lo[:, None, :] - traj) / scale
    return np.maximum(excess.max(axis=(-3, -2, -1)), 0.0)


def constraint_violations(
    problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False
) -> tuple[Violation, ...]:
    """Every violated (joint, limit) pair for one ``k`` (scalar, or (n,) with
    ``per_joint=True``), worst first; empty when the halt is within all limits (eq. 33)."""
    t = problem.times(problem.n_check)
    lo, hi = _limits(problem)
    sl = _slack(lo, hi)
    traj = np.stack(problem.trajectory(k, t, per_joint=per_joint))  # (3, n_t, n)
    over = traj - hi[:, None, :]
    under = lo[:, None, :] - traj
    out = []
    for kind_i, kind in enumerate(("angle", "velocity", "acceleration")):
        for j in range(problem.dof):
            for arr, lim in ((over, hi), (under, lo)):
                i_t = int(np.argmax(arr[kind_i, :, j]))
                excess = float(arr[kind_i, i_t, j])
                if excess > sl[kind_i, j]:
                    out.append(
                        Violation(
                            joint=problem.model.joint_numbers[j],
                            kind=kind,  # type: ignore[arg-type]
                            limit=float(lim[kind_i, j]),
                            value=float(traj[kind_i, i_t, j]),
                            excess=excess,
                            time=float(t[i_t]),
                        )
                    )
    return tuple(sorted(out, key=lambda v: -v.excess / max(abs(v.limit), 1e-300)))


def least_violating_k(problem: HaltProblem) -> float:
    """Shared ``k`` [rad/s^6] minimising the largest relative limit excess (a convex,
    piecewise-linear function of ``k``): dense scan, then bounded refinement."""
    per = feasible_k_intervals(problem)
    ends = per[np.isfinite(per)]
    span = max(float(np.abs(ends).max()) if ends.size else 0.0, 1e-12)
    grid = np.linspace(-2 * span, 2 * span, 801)
    viol = np.concatenate([relative_violation(problem, grid[i : i + 100]) for i in range(0, grid.size, 100)])
    i = int(np.argmin(viol))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = minimize_scalar(
        lambda x: float(relative_violation(problem, x)),
        bounds=(a, b),
        method="bounded",
        options={"xatol": 1e-12 * span + 1e-15},
    )
    return float(res.x) if res.fun <= viol[i] else float(grid[i])


def _start_breaks_limits(problem: HaltProblem) -> bool:
    """The state at failure itself is outside a limit (beyond the round-off slack): the halt
    starts from it (the ``k``-part and its first two derivatives vanish at ``t = 0``)."""
    lo, hi = _limits(problem)
    start = np.stack([problem.q0, problem.dq0, problem.ddq0])
    sl = _slack(lo, hi)
    return bool(np.any((start < lo - sl) | (start > hi + sl)))


def minimum_halt_time(
    problem: HaltProblem, *, t_min: float = 0.5, t_max: float | None = None, tol: float = 1e-3
) -> float | None:
    """Smallest halt time ``T`` [s] for which a feasible shared ``k`` exists.

    Scans ``T`` on a grid of 0.25 s steps from ``t_min`` to ``t_max`` (default
    ``max(10 T, 120 s)``), then bisects the first infeasible-to-feasible bracket to
    ``tol`` [s].  Returns None when no ``T`` in the range is feasible, at once when the state
    at failure itself breaks a limit (every halt starts from it, whatever ``T`` and ``k``).
    """
    if _start_breaks_limits(problem):
        return None  # the halt starts from this state whatever T and k: no T helps
    t_max = max(10 * problem.T, 120.0) if t_max is None else t_max
    grid = np.arange(t_min, t_max + 1e-9, 0.25)

    def ok(T: float) -> bool:
        lo, hi = shared_k_interval(problem.with_time(T))
        return lo <= hi

    prev = None
    for T in grid:
        if ok(float(T)):
            if prev is None:
                return float(T)
            a, b = prev, float(T)
            while b - a > tol:
                mid = 0.5 * (a + b)
                a, b = (a, mid) if ok(mid) else (mid, b)
            return b
        prev = float(T)
    return None


# -- the result and the solvers ------------------------------------------------------------


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
        Seed of a stochastic solver (GA), else None.
    problem
        The :class:`HaltProblem` solved.
    ga
        The GA run (solver ``"ga"``).
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
    seed: Any
    problem: HaltProblem = field(repr=False)
    ga: GAResult | None = field(default=None, repr=False)

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


def _scan(problem: HaltProblem, lo: float, hi: float, n_scan: int) -> tuple[float, FloatArray, FloatArray]:
    grid = np.linspace(lo, hi, n_scan)
    values = global_base_torque(problem, grid)
    i = int(np.argmin(values))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, n_scan - 1)]
    best = float(grid[i])
    if b > a:
        res = minimize_scalar(
            lambda x: float(global_base_torque(problem, x)),
            bounds=(a, b),
            method="bounded",
            options={"xatol": 1e-9 * max(abs(hi - lo), 1e-30)},
        )
        if res.fun < values[i]:
            best = float(res.x)
    return best, grid, values


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
        Seed or generator for the GA (recorded in the result).
    on_infeasible
        ``"report"``: return a result with ``feasible=False``, the least-violating ``k``, the
        violations and the smallest feasible ``T``; ``"raise"``: raise
        :class:`~jointlock.errors.InfeasibleError` with the same information.
    find_minimum_T
        Also compute the smallest feasible halt time when the problem is feasible.

    Returns
    -------
    HaltMotion
    """
    if solver not in ("scan", "ga", "vector"):
        raise ScenarioError(f"solver must be 'scan', 'ga' or 'vector'; got {solver!r}")
    if isinstance(n_scan, bool) or not isinstance(n_scan, (int, np.integer)) or n_scan < 1:
        raise ScenarioError(f"n_scan must be an integer >= 1 (grid points of the scan); got {n_scan!r}")
    bounds_k = _check_k_bounds(k_bounds)
    per = feasible_k_intervals(problem)
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
    tau0 = float(global_base_torque(problem, 0.0))
    viol0 = constraint_violations(problem, 0.0)
    settings: dict[str, Any] = {"n_scan": n_scan, "n_samples": problem.n_samples, "n_check": problem.n_check}
    if not lo <= hi:
        k = least_violating_k(problem)
        viol = constraint_violations(problem, k)
        t_min = minimum_halt_time(problem)
        result = HaltMotion(
            k=k,
            global_torque=float(global_base_torque(problem, k)),
            global_torque_k0=tau0,
            feasible=False,
            violations=viol,
            violations_k0=viol0,
            k_interval=np.array([lo, hi]),
            joint_intervals=per,
            minimum_T=t_min,
            solver=solver,
            settings=settings,
            seed=None,
            problem=problem,
        )
        msg = infeasibility_message(result)
        log.info("infeasible halt: %s", msg.splitlines()[0])
        if on_infeasible == "raise":
            raise InfeasibleError(msg)
        return result

    ga_result = None
    seed = None
    if solver == "ga":
        st = ga_settings or GASettings()
        if ga_precision is not None and hi > lo:
            st = replace(st, n_bits=bits_for_precision(lo, hi, ga_precision))
        ga_result = adaptive_ga(
            # eq. 35; the floor keeps the fitness finite where the torque vanishes
            lambda x: 1.0 / np.maximum(global_base_torque(problem, x[:, 0]), TORQUE_FLOOR),
            lo,
            hi,
            settings=st,
            rng=rng,
            progress=progress,
        )
        k: Any = float(ga_result.x[0])
        seed = ga_result.seed
        settings["ga"] = st
    else:
        k, _, _ = _scan(problem, lo, hi, n_scan)
        if solver == "vector":
            bounds = [(float(a), float(b)) for a, b in per]
            x0 = np.clip(np.full(problem.dof, k), per[:, 0], per[:, 1])
            scale = max(hi - lo, 1e-12)
            res = minimize(
                lambda x: float(global_base_torque(problem, x * scale, per_joint=True)),
                x0 / scale,
                method="Powell",
                bounds=[(a / scale, b / scale) for a, b in bounds],
                options={"xtol": 1e-6, "ftol": 1e-10},
            )
            kv = np.clip(res.x * scale, per[:, 0], per[:, 1])
            k = (
                kv
                if global_base_torque(problem, kv, per_joint=True) <= global_base_torque(problem, k)
                else np.full(problem.dof, k)
            )
            settings["scipy"] = {"method": "Powell", "nfev": int(res.nfev), "message": str(res.message)}
    per_joint = np.ndim(k) == 1
    tau = float(global_base_torque(problem, k, per_joint=per_joint))
    viol = constraint_violations(problem, k, per_joint=per_joint)
    return HaltMotion(
        k=k,
        global_torque=tau,
        global_torque_k0=tau0,
        feasible=not viol,
        violations=viol,
        violations_k0=viol0,
        k_interval=np.array([lo, hi]),
        joint_intervals=per,
        minimum_T=minimum_halt_time(problem) if find_minimum_T else None,
        solver=solver,
        settings=settings,
        seed=seed,
        problem=problem,
        ga=ga_result,
    )


def infeasibility_message(result: HaltMotion, *, k_unit: str = "deg/s^6") -> str:
    """Plain-language verdict for an infeasible halt: which joint, which limit, by how much,
    and the smallest halt time with a feasible ``k``."""
    scale = K_UNIT_SCALE[k_unit]
    p = result.problem
    k = ", ".join(f"{v:.6g}" for v in np.atleast_1d(np.asarray(result.k, dtype=float) / scale))
    lines = [
        f"no k satisfies the limits for a {p.T:g} s halt: every value of k breaks at least one limit.",
        f"least-violating k = {k} {k_unit}; there:",
    ]
    lines += ["  " + v.describe() for v in result.violations[:6]]
    if result.minimum_T is not None:
        lines.append(f"smallest halt time with a feasible k: T = {result.minimum_T:.3f} s")
    elif _start_breaks_limits(p):
        lines.append("the state at failure already breaks a limit (at t = 0): no halt time or k helps")
    else:
        lines.append("no halt time up to the search limit has a feasible k")
    return "\n".join(lines)
