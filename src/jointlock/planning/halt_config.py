"""Optimal halt configuration (seed 000 §3.2 and §5.1): HCOM by Monte Carlo, then a bounded
local refinement, with an optional reachability bound and the section plots of 000 Fig. 7.

The search (000 eqs. 20-24): sample ``K`` configurations of the healthy joints uniformly within
their limits (eq. 21), evaluate the combined kinematic-ability index CP of every sample in
batched calls (eq. 19, :mod:`jointlock.analysis.ability`), keep the best.  The normalisation of
CP (min-max bounds of ``s`` and ``w``) and its weights (AHP + entropy) depend on the sample
set; they are fitted once and then *frozen*, so that the refinement and any later evaluation
score configurations on the same scale.

Beyond the paper: the best ``refine_starts`` samples are polished by a bounded quasi-Newton
search (``scipy.optimize.minimize``, L-BFGS-B, central-difference gradients evaluated in one
batched call).  The result is never worse than the best sample, and the gain is reported.
"""

from __future__ import annotations

import functools
import logging
import math
import secrets
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..analysis.ability import (
    DEFAULT_BATCH,
    INDEX_NAMES,
    PAPER_JUDGMENT,
    AbilityModel,
    Assignment,
    JacobianKind,
    KinematicIndices,
    RITable,
    configuration_indices,
    fit_ability_model,
)
from ..errors import ConfigurationError, InfeasibleError
from ..model import ArmModel, FloatArray, as_joint_array
from ..progress import Progress
from .halt_motion import LIMIT_RTOL, AffineKBounds, KIntervalBatch

logger = logging.getLogger(__name__)

#: Central-difference step of the refinement's gradient [rad]; CP is smooth away from
#: singular-value crossings, truncation error ~ h^2 (1e-12), round-off ~ eps / h (1e-10).
REFINE_FD_STEP = 1e-6
#: Default minimum separation of the runner-up from the best configuration (largest joint
#: difference) [rad]: 10 deg, so that the runner-up is another configuration, not the best
#: one nudged.
RUNNER_UP_SEPARATION = math.radians(10.0)


#: Two configurations whose CP differ by less than this (relative) are equivalents of one
#: another, not a runner-up [-] (refined starts agree to ~1e-10 at a common optimum).
EQUIVALENT_CP_RTOL = 1e-6


def _readonly(a: ArrayLike) -> FloatArray:
    out = np.array(a, dtype=float)
    out.setflags(write=False)
    return out


# -- reachability bound -----------------------------------------------------------------------


@dataclass(frozen=True)
class ReachabilityBound:
    """Where each healthy joint can come to rest within a halt time under speed and
    acceleration limits: a necessary condition for a halt configuration.

    For one joint starting at ``q0`` with rate ``dq0``, the positions at which it can be at
    rest by time ``T`` with ``|dq| <= v_max`` and ``|ddq| <= a_max`` form an interval
    ``[q0 + d_-, q0 + d_+]``.  ``d_+`` is reached by the bang-bang profile (accelerate at
    ``a_max`` to a peak speed, cruise at ``v_max`` if reached, brake at ``a_max`` to rest at
    ``T``); ``d_- = -d_+(-dq0)``.  The feasible velocity profiles form a convex set, so every
    point between is reachable too.  The bound ignores the initial acceleration ``ddq0`` and
    jerk, so it is an *outer* bound for smooth profiles such as 000's 6th-order polynomial
    (issue 4 checks a specific motion); ``ddq0`` is recorded only.

    Attributes
    ----------
    q0, dq0
        (n,) healthy-joint angles [rad] and rates [rad/s] at the start of the halt.
    halt_time
        ``T = t_f - t_0`` [s].
    velocity_limit, acceleration_limit
        (n,) ``v_max`` [rad/s] and ``a_max`` [rad/s^2] (symmetric limits).
    ddq0
        (n,) accelerations [rad/s^2] at the start (recorded, not used by the bound).
    """

    q0: FloatArray
    dq0: FloatArray
    halt_time: float
    velocity_limit: FloatArray
    acceleration_limit: FloatArray
    ddq0: FloatArray | None = None

    def __post_init__(self) -> None:
        q0 = np.asarray(self.q0, dtype=float)
        n = q0.shape[-1] if q0.ndim == 1 else -1
        if q0.ndim != 1 or not np.all(np.isfinite(q0)):
            raise ConfigurationError(f"q0 must be a finite vector (n,) [rad]; got shape {q0.shape}")

        def vec(name: str, value: Any, positive: bool) -> FloatArray:
            arr = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
            if not np.all(np.isfinite(arr) | (positive & np.isposinf(arr))):
                raise ConfigurationError(f"{name} must be finite; got {arr.tolist()}")
            if positive and np.any(arr <= 0):
                raise ConfigurationError(f"{name} must be > 0; got {arr.tolist()}")
            return _readonly(arr)

        try:
            dq0 = vec("dq0 [rad/s]", self.dq0, False)
            vmax = vec("velocity_limit [rad/s]", self.velocity_limit, True)
            amax = vec("acceleration_limit [rad/s^2]", self.acceleration_limit, True)
            ddq0 = None if self.ddq0 is None else vec("ddq0 [rad/s^2]", self.ddq0, False)
        except ValueError as exc:
            raise ConfigurationError(f"reachability: vectors must have {n} entries like q0; {exc}") from None
        if not np.all(np.isfinite(amax)):
            raise ConfigurationError("acceleration_limit must be finite [rad/s^2]")
        t = float(self.halt_time)
        if not (math.isfinite(t) and t > 0):
            raise ConfigurationError(f"halt_time must be a finite time > 0 [s]; got {self.halt_time!r}")
        object.__setattr__(self, "q0", _readonly(q0))
        object.__setattr__(self, "dq0", dq0)
        object.__setattr__(self, "velocity_limit", vmax)
        object.__setattr__(self, "acceleration_limit", amax)
        object.__setattr__(self, "ddq0", ddq0)
        object.__setattr__(self, "halt_time", t)

    def interval(self, joint_numbers: tuple[int, ...] | None = None) -> tuple[FloatArray, FloatArray]:
        """(n,) lowest and highest reachable rest angles [rad].

        Raises
        ------
        InfeasibleError
            A joint starts faster than its speed limit, or cannot stop within ``T``
            (``|dq0| > a_max T``); the message names the joint, by how much, and the
            smallest halt time that would do.
        """
        numbers = joint_numbers or tuple(range(1, self.q0.size + 1))
        v0, vmax, amax, t = self.dq0, self.velocity_limit, self.acceleration_limit, self.halt_time
        over = np.abs(v0) - vmax
        if np.any(over > 0):
            i = int(np.argmax(over))
            raise InfeasibleError(
                f"joint {numbers[i]} starts at {math.degrees(abs(v0[i])):.4g} deg/s, above its speed "
                f"limit {math.degrees(vmax[i]):.4g} deg/s by {math.degrees(over[i]):.4g} deg/s"
            )
        t_stop = np.abs(v0) / amax
        if np.any(t_stop > t):
            i = int(np.argmax(t_stop - t))
            raise InfeasibleError(
                f"joint {numbers[i]} cannot stop within the halt time T = {t:.4g} s: braking from "
                f"{math.degrees(abs(v0[i])):.4g} deg/s at {math.degrees(amax[i]):.4g} deg/s^2 takes "
                f"{t_stop[i]:.4g} s ({t_stop[i] - t:.4g} s too long); the smallest feasible T is "
                f"{float(t_stop.max()):.4g} s"
            )
        return self.q0 - _max_rest_displacement(-v0, vmax, amax, t), self.q0 + _max_rest_displacement(
            v0, vmax, amax, t
        )

    def contains(self, q: ArrayLike) -> np.ndarray:
        """(...) bool: configurations (..., n) [rad] inside the reachable box."""
        lo, hi = self.interval()
        q = np.asarray(q, dtype=float)
        return np.all((q >= lo) & (q <= hi), axis=-1)


def _max_rest_displacement(v0: FloatArray, vmax: FloatArray, amax: FloatArray, t: float) -> FloatArray:
    """Largest displacement [rad] ending at rest by time ``t`` (bang-bang with cruise)."""
    peak = 0.5 * (amax * t + v0)  # accelerate then brake, meeting at the peak at time t
    no_cruise = (2.0 * peak**2 - v0**2) / (2.0 * amax)
    vm = np.where(np.isfinite(vmax), vmax, 0.0)
    t_cruise = t - (vm - v0) / amax - vm / amax
    cruise = (vm**2 - v0**2) / (2.0 * amax) + vm**2 / (2.0 * amax) + vm * t_cruise
    return np.where(peak <= vmax, no_cruise, cruise)


@dataclass(frozen=True)
class HaltReachability:
    """Exact reachability of a halt configuration by 000's halt polynomial (eq. 27): the
    halt from the state ``(q0, dq0, ddq0)`` to ``qf`` in the halt time ``T`` must respect the
    angle, speed and acceleration limits for some ``k`` (a shared ``k`` as 000, or one ``k``
    per joint), checked on the same time grid as :class:`~jointlock.planning.halt_motion.HaltProblem`.

    Unlike :class:`ReachabilityBound` (bang-bang, necessary only) a configuration that passes
    has a feasible halt motion.  Every limit is affine in ``k`` and in ``qf``
    (:class:`~jointlock.planning.halt_motion.AffineKBounds`), so whole sample sets are checked
    in one batched call, the reachable set is convex, and its bounding box is computed
    exactly (to a grid per joint) before sampling.

    Attributes
    ----------
    q0, dq0, ddq0
        (n,) healthy-joint angles [rad], rates [rad/s], accelerations [rad/s^2] at the start.
    halt_time
        ``T`` [s].
    velocity_limit, acceleration_limit
        (n,) ``v_max`` [rad/s] and ``a_max`` [rad/s^2] (symmetric limits).
    per_joint
        False (000): one shared ``k``; True: one ``k`` per joint (then the set is a box).
    angle_lower, angle_upper
        (n,) angle limits [rad] of the halt; None: the model's (filled in by
        :func:`optimal_halt_configuration`, as ``HaltProblem`` does).  ``-inf``/``+inf``
        (a continuous joint): no angle constraint for that joint.
    n_check
        Time grid of the check (``HaltProblem.n_check``).
    margin
        Relative margin for the search [-]: a configuration is accepted when its feasible
        ``k`` interval is at least this fraction of ``max(|k_min|, |k_max|)`` wide, so that
        the halt-motion solver (same limits, other round-off) finds a non-degenerate interval.
    n_grid
        Grid points per joint of the bounding box.
    """

    q0: FloatArray
    dq0: FloatArray
    ddq0: FloatArray
    halt_time: float
    velocity_limit: FloatArray
    acceleration_limit: FloatArray
    per_joint: bool = False
    angle_lower: FloatArray | None = None
    angle_upper: FloatArray | None = None
    n_check: int = 2001
    margin: float = 1e-6
    n_grid: int = 4001

    def __post_init__(self) -> None:
        b = ReachabilityBound(
            self.q0, self.dq0, self.halt_time, self.velocity_limit, self.acceleration_limit, self.ddq0
        )
        if b.ddq0 is None:
            raise ConfigurationError("ddq0 is required [rad/s^2] (zeros for a start without acceleration)")
        if not np.all(np.isfinite(b.velocity_limit)):
            raise ConfigurationError("velocity_limit must be finite [rad/s]")
        for name in ("q0", "dq0", "ddq0", "halt_time", "velocity_limit", "acceleration_limit"):
            object.__setattr__(self, name, getattr(b, name))
        n = b.q0.size
        for name in ("angle_lower", "angle_upper"):
            v = getattr(self, name)
            if v is not None:
                arr = np.broadcast_to(np.asarray(v, dtype=float), (n,))
                if np.any(np.isnan(arr)):  # -inf/+inf: a joint without an angle limit
                    raise ConfigurationError(
                        f"{name} must be angles [rad] (-inf/+inf for no limit), not NaN; got {arr.tolist()}"
                    )
                object.__setattr__(self, name, _readonly(arr))
        if not (isinstance(self.margin, (int, float)) and 0 <= self.margin < 0.1):
            raise ConfigurationError(f"margin must be in [0, 0.1); got {self.margin!r}")
        if int(self.n_check) < 3 or int(self.n_grid) < 3:
            raise ConfigurationError("n_check and n_grid must be >= 3")
        object.__setattr__(self, "per_joint", bool(self.per_joint))

    def bound(self) -> ReachabilityBound:
        """The bang-bang outer bound of the same state and limits."""
        return ReachabilityBound(
            self.q0, self.dq0, self.halt_time, self.velocity_limit, self.acceleration_limit, self.ddq0
        )

    def bind(self, model: ArmModel) -> HaltReachability:
        """This constraint with the model's angle limits where none were given."""
        if self.q0.shape != (model.dof,):
            raise ConfigurationError(
                f"reachability.q0 must have {model.dof} entries (joints {list(model.joint_numbers)}); "
                f"got {self.q0.shape}"
            )
        lo = model.lower if self.angle_lower is None else self.angle_lower
        hi = model.upper if self.angle_upper is None else self.angle_upper
        return replace(self, angle_lower=lo, angle_upper=hi)

    def bounds(self, T: float | None = None) -> AffineKBounds:
        """The limits as bounds on ``k`` affine in ``qf`` (for ``T``, default :attr:`halt_time`).

        The bounds of :attr:`halt_time` are built once per instance and shared (treat them as
        read-only); another ``T`` builds new ones.
        """
        if T is None or float(T) == self.halt_time:
            return self._bounds_at_halt_time
        return self._build_bounds(float(T))

    def _build_bounds(self, T: float) -> AffineKBounds:
        return AffineKBounds(
            self.q0,
            self.dq0,
            self.ddq0,
            T,
            self.velocity_limit,
            self.acceleration_limit,
            self.angle_lower,
            self.angle_upper,
            n_check=self.n_check,
        )

    @functools.cached_property
    def _bounds_at_halt_time(self) -> AffineKBounds:
        # a cache in the instance __dict__, not a field: equality, hash and repr are unchanged,
        # and dataclasses.replace (e.g. bind) builds a fresh instance without it
        return self._build_bounds(self.halt_time)

    def start_violations(self, joint_numbers: tuple[int, ...] | None = None) -> list[str]:
        """Limits the state at failure itself breaks (angle, velocity or acceleration outside its
        range at ``t = 0``), one plain-language line each; empty when none.

        The halt polynomial starts from that state whatever ``T`` and ``k`` (the ``k``-part
        and its first two derivatives vanish at ``t = 0``), so any such line means no halt
        time or ``k`` helps.  The angle is checked only once angle limits are known
        (:meth:`bind`).  Same slack as the halt-motion check (``LIMIT_RTOL``).
        """
        numbers = joint_numbers or tuple(range(1, self.q0.size + 1))
        checks = [
            ("velocity", "deg/s", self.dq0, -self.velocity_limit, self.velocity_limit),
            ("acceleration", "deg/s^2", self.ddq0, -self.acceleration_limit, self.acceleration_limit),
        ]
        if self.angle_lower is not None and self.angle_upper is not None:
            checks.insert(0, ("angle", "deg", self.q0, self.angle_lower, self.angle_upper))
        out = []
        for quantity, unit, value, lo, hi in checks:
            lo_f, hi_f = np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0)
            slack = LIMIT_RTOL * np.maximum(np.maximum(np.abs(lo_f), np.abs(hi_f)), 1.0)
            for i in np.nonzero((value < lo - slack) | (value > hi + slack))[0]:
                out.append(
                    f"joint {numbers[i]} starts with {quantity} {math.degrees(value[i]):.6g} {unit}, "
                    f"outside its allowed range [{math.degrees(lo[i]):.6g}, {math.degrees(hi[i]):.6g}] {unit}"
                )
        return out

    def check_start(self, joint_numbers: tuple[int, ...] | None = None) -> None:
        """Raise :class:`~jointlock.errors.InfeasibleError` when the state at failure itself
        breaks a limit (:meth:`start_violations`): no halt time or ``k`` helps then."""
        bad = self.start_violations(joint_numbers)
        if bad:
            raise InfeasibleError(
                "the state at failure already breaks a limit, and every halt starts from it, so no "
                "halt time or k helps: " + "; ".join(bad)
            )

    def intervals(self, q: ArrayLike) -> KIntervalBatch:
        """Feasible ``k`` [rad/s^6] of the halt to each configuration (K, n) [rad]."""
        return self.bounds().intervals(q)

    def contains(self, q: ArrayLike) -> np.ndarray:
        """(...) bool: configurations (..., n) [rad] reachable, with the :attr:`margin`."""
        iv = self.intervals(q)
        if self.per_joint:
            lo, hi = iv.joint[..., 0], iv.joint[..., 1]
            return np.all(hi - lo >= self.margin * np.maximum(np.abs(lo), np.abs(hi)), axis=-1)
        width = iv.upper - iv.lower
        return iv.feasible & (width >= self.margin * np.maximum(np.abs(iv.lower), np.abs(iv.upper)))

    def search_box(
        self, lower: ArrayLike, upper: ArrayLike, T: float | None = None
    ) -> tuple[FloatArray, FloatArray, tuple[float, float] | None, FloatArray] | None:
        """Bounding box of the reachable configurations within ``[lower, upper]`` (the
        bang-bang bound narrows it first), the feasible shared ``k`` range and a reachable
        configuration; None when none is reachable (see
        :meth:`AffineKBounds.configuration_box`)."""
        t = self.halt_time if T is None else float(T)
        lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        if self.start_violations():  # no T or k helps (see check_start)
            return None
        try:
            r_lo, r_hi = replace(self.bound(), halt_time=t).interval()
        except InfeasibleError:
            return None
        lo, hi = np.maximum(lo, r_lo), np.minimum(hi, r_hi)
        if np.any(hi < lo):
            return None
        return self.bounds(t).configuration_box(lo, hi, per_joint=self.per_joint, n_grid=self.n_grid)

    def minimum_halt_time(
        self,
        lower: ArrayLike,
        upper: ArrayLike,
        *,
        step: float = 0.25,
        t_max: float | None = None,
        tol: float = 1e-3,
    ) -> float | None:
        """Smallest halt time [s] for which some configuration in ``[lower, upper]`` is
        reachable: scan in ``step`` from the braking time ``max |dq0| / a_max``, then bisect
        to ``tol`` (None when none up to ``t_max``, default ``max(10 T, 120 s)``)."""
        if self.start_violations():  # the start breaks a limit: no T helps (see check_start)
            return None
        t_stop = float(np.max(np.abs(self.dq0) / self.acceleration_limit))
        t_max = max(10 * self.halt_time, 120.0) if t_max is None else t_max

        def ok(t: float) -> bool:
            return self.search_box(lower, upper, t) is not None

        prev = t_stop
        t = max(t_stop, step)
        while t <= t_max + 1e-9:
            if ok(t):
                a, b = prev, t
                while b - a > tol:
                    mid = 0.5 * (a + b)
                    a, b = (a, mid) if ok(mid) else (mid, b)
                return b
            prev, t = t, t + step
        return None

    def describe_state(self) -> str:
        """The state and limits in degrees, for messages."""

        def fmt(v: FloatArray) -> str:
            return "[" + ", ".join(f"{x:.4g}" for x in np.degrees(v)) + "]"

        return (
            f"q0 = {fmt(self.q0)} deg, dq0 = {fmt(self.dq0)} deg/s, ddq0 = {fmt(self.ddq0)} deg/s^2, "
            f"|dq| <= {fmt(self.velocity_limit)} deg/s, |ddq| <= {fmt(self.acceleration_limit)} deg/s^2"
        )


# -- result -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class HaltCandidate:
    """One configuration and its kinematic ability.

    Attributes
    ----------
    q
        (n,) healthy-joint angles [rad], chain order (``joint_numbers`` of the result).
    cp
        Combined index CP (000 eq. 19) on the frozen scale of the sample set.
    sigma_min, condition_number, manipulability
        The unilateral indices (000 Table 3) at ``q``, computed by SVD.
    """

    q: FloatArray
    cp: float
    sigma_min: float
    condition_number: float
    manipulability: float

    def to_dict(self) -> dict[str, Any]:
        """Plain data, angles in degrees."""
        return {
            "q_deg": np.degrees(self.q).tolist(),
            "cp": self.cp,
            "sigma_min": self.sigma_min,
            "condition_number": self.condition_number,
            "manipulability": self.manipulability,
        }


@dataclass(frozen=True)
class HaltConfiguration:
    """Result of :func:`optimal_halt_configuration`.

    Attributes
    ----------
    best
        The optimal halt configuration (after refinement when enabled).
    best_sample
        The best of the ``samples`` Monte Carlo configurations (000's answer).
    runner_up
        The best configuration at least ``runner_up_separation`` away from ``best`` (largest
        joint difference) and not equivalent to it (CP differing by more than
        :data:`EQUIVALENT_CP_RTOL`), among refined candidates and samples; None if none.
    refinement_gain
        ``best.cp - best_sample.cp`` (>= 0; 0 without refinement).
    ability
        CP's frozen normalisation and weights (AHP, entropy, combined).
    samples
        ``K``.
    seed
        The seed of the generator (an int) or None when a ``Generator`` was passed.
    jacobian, base
        Jacobian used (``"generalized"`` / ``"fixed"``) and the model's base
        (``"floating"`` / ``"fixed"``); the generalized Jacobian of a fixed base is the
        fixed-base Jacobian.
    joint_numbers
        Numbers (1-based, full arm) of the healthy joints, the order of every ``q``.
    locked
        ``{joint number: angle [rad]}``.
    lower, upper
        (n,) the box that was sampled [rad] (limits, intersected with the reachable box).
    characteristic_length
        ``L`` [m] or None (raw Jacobian, as 000).
    reachability
        The reachability constraint applied (:class:`HaltReachability`, exact, or
        :class:`ReachabilityBound`, bang-bang box only), or None.
    q_samples, cp_samples
        (K, n) [rad] and (K,): the sample set and its CP.
    indices_samples
        Indices of the sample set, arrays (K,).
    refine_evaluations
        Configurations evaluated by the refinement.
    reachable
        (K,) bool: samples whose halt motion is feasible (:class:`HaltReachability`), or
        None.  Unreachable samples keep their CP (the normalisation and entropy weights are
        fitted on the whole sample set) but can be neither the best nor the runner-up.
    reachable_samples
        How many samples are reachable (None without :class:`HaltReachability`).
    k_range
        Feasible shared ``k`` [rad/s^6] over the reachable set (shared-``k`` constraint only).
    """

    best: HaltCandidate
    best_sample: HaltCandidate
    runner_up: HaltCandidate | None
    refinement_gain: float
    ability: AbilityModel
    samples: int
    seed: int | None
    jacobian: JacobianKind
    base: Literal["fixed", "floating"]
    joint_numbers: tuple[int, ...]
    locked: dict[int, float]
    lower: FloatArray
    upper: FloatArray
    characteristic_length: float | None
    reachability: ReachabilityBound | HaltReachability | None
    q_samples: FloatArray = field(repr=False)
    cp_samples: FloatArray = field(repr=False)
    indices_samples: KinematicIndices = field(repr=False)
    refine_evaluations: int = 0
    reachable: np.ndarray | None = field(default=None, repr=False)
    reachable_samples: int | None = None
    k_range: tuple[float, float] | None = None

    @property
    def q_best(self) -> FloatArray:
        """(n,) the optimal halt configuration, healthy joints [rad]."""
        return self.best.q

    @property
    def cp_best(self) -> float:
        """CP at :attr:`q_best`."""
        return self.best.cp

    @property
    def weights(self) -> dict[str, dict[str, float]]:
        """``{"ahp" | "entropy" | "combined": {index name: weight}}``."""
        return self.ability.weights_dict()

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON (degrees for angles; the samples themselves are left out)."""
        ahp = self.ability.ahp
        return {
            "best": self.best.to_dict(),
            "best_sample": self.best_sample.to_dict(),
            "runner_up": None if self.runner_up is None else self.runner_up.to_dict(),
            "refinement": {
                "gain": self.refinement_gain,
                "relative_gain": self.refinement_gain / abs(self.best_sample.cp)
                if self.best_sample.cp
                else None,
                "evaluations": self.refine_evaluations,
            },
            "weights": self.weights,
            "ahp": {
                "matrix": ahp.matrix.tolist(),
                "lambda_max": ahp.lambda_max,
                "ci": ahp.ci,
                "cr": ahp.cr,
                "ri": ahp.ri,
            },
            "entropy": {
                "entropy": dict(zip(INDEX_NAMES, self.ability.entropy.entropy.tolist())),
                "divergence": dict(zip(INDEX_NAMES, self.ability.entropy.divergence.tolist())),
            },
            "normalization": {
                "sigma_min": list(self.ability.normalization.sigma_min_range),
                "manipulability": list(self.ability.normalization.manipulability_range),
            },
            "readings": {"assignment": self.ability.assignment, "renormalize": self.ability.renormalize},
            "seed": self.seed,
            "samples": self.samples,
            "jacobian": self.jacobian,
            "base": self.base,
            "characteristic_length_m": self.characteristic_length,
            "joint_numbers": list(self.joint_numbers),
            "locked_deg": {str(k): math.degrees(v) for k, v in self.locked.items()},
            "lower_deg": np.degrees(self.lower).tolist(),
            "upper_deg": np.degrees(self.upper).tolist(),
            "reachability": self._reachability_dict(),
        }

    def _reachability_dict(self) -> dict[str, Any] | None:
        r = self.reachability
        if r is None:
            return None
        out: dict[str, Any] = {
            "kind": "exact" if isinstance(r, HaltReachability) else "bang-bang bound",
            "halt_time_s": r.halt_time,
            "q0_deg": np.degrees(r.q0).tolist(),
            "dq0_deg": np.degrees(r.dq0).tolist(),
            "ddq0_deg": None if r.ddq0 is None else np.degrees(r.ddq0).tolist(),
            "velocity_limit_deg": np.degrees(r.velocity_limit).tolist(),
            "acceleration_limit_deg": np.degrees(r.acceleration_limit).tolist(),
        }
        if isinstance(r, HaltReachability):
            scale = math.pi / 180.0  # k in deg/s^6, 000's reading
            out.update(
                per_joint_k=r.per_joint,
                reachable_samples=self.reachable_samples,
                k_range_deg_s6=None if self.k_range is None else [v / scale for v in self.k_range],
            )
        return out


# -- the search -------------------------------------------------------------------------------


def _resolve_rng(rng: int | np.random.Generator | None) -> tuple[np.random.Generator, int | None]:
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is None:
        seed = secrets.randbits(63)
    elif isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and int(rng) >= 0:
        seed = int(rng)
    else:
        raise ConfigurationError(
            f"rng must be None, a non-negative int seed or a numpy Generator; got {rng!r}"
        )
    return np.random.default_rng(seed), seed


def _sampling_box(
    model: ArmModel,
    lower: ArrayLike | None,
    upper: ArrayLike | None,
    reachability: ReachabilityBound | None,
) -> tuple[FloatArray, FloatArray]:
    n = model.dof
    lo = np.maximum(model.lower, -math.pi) if lower is None else np.asarray(lower, dtype=float)
    hi = np.minimum(model.upper, math.pi) if upper is None else np.asarray(upper, dtype=float)
    for name, arr in (("lower", lo), ("upper", hi)):
        if arr.shape != (n,) or not np.all(np.isfinite(arr)):
            raise ConfigurationError(
                f"{name} must be {n} finite angles [rad] (joints {list(model.joint_numbers)}); "
                f"got {np.asarray(arr).tolist()}"
            )
    if reachability is not None:
        if reachability.q0.shape != (n,):
            raise ConfigurationError(
                f"reachability.q0 must have {n} entries (joints {list(model.joint_numbers)}); "
                f"got {reachability.q0.shape}"
            )
        r_lo, r_hi = reachability.interval(model.joint_numbers)
        lo, hi = np.maximum(lo, r_lo), np.minimum(hi, r_hi)
    empty = hi < lo
    if np.any(empty):
        i = int(np.argmax(lo - hi))
        raise InfeasibleError(
            f"no admissible angle for joint {model.joint_numbers[i]}: the reachable range misses the "
            f"joint limits by {math.degrees(lo[i] - hi[i]):.4g} deg (lower {math.degrees(lo[i]):.4g} "
            f"deg > upper {math.degrees(hi[i]):.4g} deg)"
        )
    return _readonly(lo), _readonly(hi)


def _candidate(q: FloatArray, cp: float, ind: KinematicIndices) -> HaltCandidate:
    return HaltCandidate(
        _readonly(q),
        float(cp),
        float(ind.sigma_min),
        float(ind.condition_number),
        float(ind.manipulability),
    )


def optimal_halt_configuration(
    model_locked: ArmModel,
    *,
    samples: int = 36000,
    rng: int | np.random.Generator | None = None,
    jacobian: JacobianKind = "generalized",
    refine: bool = True,
    refine_starts: int = 8,
    assignment: Assignment = "equation",
    renormalize: bool = False,
    judgment: ArrayLike = PAPER_JUDGMENT,
    ri: RITable = "paper",
    characteristic_length: float | None = None,
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
    reachability: ReachabilityBound | HaltReachability | None = None,
    runner_up_separation: float = RUNNER_UP_SEPARATION,
    batch_size: int = DEFAULT_BATCH,
    progress: Progress | None = None,
) -> HaltConfiguration:
    """Optimal halt configuration of an arm with locked joints (000 HCOM, eqs. 19-24).

    Parameters
    ----------
    model_locked
        The arm after the lock (:func:`jointlock.lock`); its movable joints are the healthy
        joints searched over.
    samples
        ``K``, Monte Carlo samples (000: 36000), K >= 2.
    rng
        Seed or ``numpy.random.Generator``; None draws a fresh seed, which is recorded.
    jacobian
        ``"generalized"`` (default): 000 §3.1.2 analyses the generalized Jacobian ``J~_F`` of
        the free-floating arm (eq. 5), which is also what the crippled arm's operator sees in
        orbit.  A fixed-base model has no spacecraft to react, and its generalized Jacobian is
        the fixed-base one; load the robot with ``base="floating"`` for 000's ``J_F``.
        ``"fixed"``: the geometric Jacobian with the base held, whatever the model.
    refine
        Polish the best ``refine_starts`` samples with L-BFGS-B inside the box, CP's
        normalisation and weights frozen from the sample set; the best is never worse than
        the best sample.
    assignment, renormalize, judgment, ri
        Readings of 000's ambiguities and the AHP inputs, see
        :mod:`jointlock.analysis.ability`.  Defaults: eq. (19)'s index order
        (``"equation"``: the condition number receives the AHP weight 1/2), weights summed as
        printed in eq. (18) (not renormalised), 000's judgment matrix eq. (39) and RI table.
    characteristic_length
        ``L`` [m] to scale the Jacobian's linear rows; None (000) uses the raw matrix.
    lower, upper
        (n,) sampling box [rad]; default the joint limits capped to +-pi (000: [-180, 180] deg),
        so a joint without angle limits (continuous, limits +-inf) is sampled over [-pi, pi]
        (every angle, once) and has no angle constraint in the reachability check.
    reachability
        :class:`HaltReachability` (exact): only configurations that 000's halt polynomial
        reaches from the given state within ``T`` under the limits.  The sampling box is the
        bounding box of the reachable set (within the bang-bang bound and ``lower``/``upper``);
        samples outside the set are masked (they cannot be the best or the runner-up); the
        refinement keeps the constraint (a refined point that leaves the set is pulled back
        along the segment from its start, which is reachable, the set being convex).
        :class:`ReachabilityBound` (bang-bang, necessary only): the box is intersected with
        each joint's reachable rest angles.
    runner_up_separation
        Minimum largest-joint difference of the runner-up from the best [rad].
    batch_size
        Samples per batched evaluation.
    progress
        Optional progress bar (advanced per batch).

    Returns
    -------
    HaltConfiguration

    Raises
    ------
    InfeasibleError
        When the reachability bound leaves no admissible angle for some joint, or no
        configuration is reachable under :class:`HaltReachability` (the message gives the
        state, ``T`` and the smallest halt time with a reachable configuration), or none of
        the samples is.
    """
    from scipy.optimize import minimize

    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ConfigurationError(f"samples must be an integer >= 2; got {samples!r}")
    if jacobian not in ("generalized", "fixed"):
        raise ConfigurationError(f"jacobian must be 'generalized' or 'fixed'; got {jacobian!r}")
    if int(refine_starts) < 1:
        raise ConfigurationError(f"refine_starts must be >= 1; got {refine_starts!r}")
    generator, seed = _resolve_rng(rng)
    exact_reach: HaltReachability | None = None
    k_range = None
    if isinstance(reachability, HaltReachability):
        exact_reach = reachability = reachability.bind(model_locked)
        exact_reach.check_start(model_locked.joint_numbers)  # impossible starts, up front
        lo, hi = _sampling_box(model_locked, lower, upper, None)
        try:  # the bang-bang bound's own verdict (a joint cannot stop within T) is precise
            exact_reach.bound().interval(model_locked.joint_numbers)
        except InfeasibleError as exc:
            raise InfeasibleError(
                _unreachable_message(exact_reach, lo, hi, model_locked.joint_numbers, reason=str(exc))
            ) from None
        box = exact_reach.search_box(lo, hi)
        if box is None:
            raise InfeasibleError(_unreachable_message(exact_reach, lo, hi, model_locked.joint_numbers))
        lo, hi, k_range, _ = box
        lo, hi = _readonly(lo), _readonly(hi)
    else:
        lo, hi = _sampling_box(model_locked, lower, upper, reachability)
    n = model_locked.dof
    k = int(samples)

    q = lo + (hi - lo) * generator.random((k, n))  # 000 eq. (21)-(22), one row per sample
    reachable = None if exact_reach is None else exact_reach.contains(q)
    if reachable is not None and not reachable.any():
        raise InfeasibleError(
            f"none of the {k} samples is reachable within T = {exact_reach.halt_time:g} s, although "
            f"reachable configurations exist in the box [{', '.join(f'{v:.4g}' for v in np.degrees(lo))}] .. "
            f"[{', '.join(f'{v:.4g}' for v in np.degrees(hi))}] deg (a thin set): increase samples or T"
        )
    opts = {"jacobian": jacobian, "characteristic_length": characteristic_length}
    ind = configuration_indices(
        model_locked, q, method="gram", batch_size=batch_size, progress=progress, **opts
    )
    ability = fit_ability_model(ind, judgment=judgment, assignment=assignment, renormalize=renormalize, ri=ri)
    cp = ability(ind)
    order = np.argsort(-cp if reachable is None else np.where(reachable, -cp, np.inf), kind="stable")
    n_ok = k if reachable is None else int(reachable.sum())

    def exact(qs: FloatArray) -> tuple[FloatArray, KinematicIndices]:
        i = configuration_indices(model_locked, qs, method="svd", **opts)
        return ability(i), i

    cp0, ind0 = exact(q[order[0]])
    best_sample = _candidate(q[order[0]], cp0, ind0)

    refined_q: list[FloatArray] = []
    refined_cp: list[float] = []
    evaluations = 0
    if refine:
        steps = REFINE_FD_STEP * np.vstack([np.zeros(n), np.eye(n), -np.eye(n)])  # (2n+1, n)

        def fun(x: FloatArray) -> tuple[float, FloatArray]:
            nonlocal evaluations
            pts = np.clip(x + steps, lo, hi)
            val, _ = exact(pts)
            evaluations += pts.shape[0]
            h = np.diagonal(pts[1 : n + 1]) - np.diagonal(pts[n + 1 :])  # per-joint step
            grad = np.divide(val[1 : n + 1] - val[n + 1 :], h, out=np.zeros(n), where=h > 0)
            return -float(val[0]), -grad

        for idx in order[: min(int(refine_starts), n_ok)]:
            res = minimize(fun, q[idx], jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi)))
            x = np.clip(res.x, lo, hi)
            if exact_reach is not None and not exact_reach.contains(x):
                x = _pull_back(exact_reach, q[idx], x)
                evaluations += 1
            refined_q.append(x)
            refined_cp.append(float(exact(x)[0]))
    best = best_sample
    if refined_cp and max(refined_cp) > best_sample.cp:
        j = int(np.argmax(refined_cp))
        c, i = exact(refined_q[j])
        best = _candidate(refined_q[j], c, i)

    pool_q = np.vstack([np.asarray(refined_q).reshape(-1, n), q if reachable is None else q[reachable]])
    pool_cp = np.concatenate(
        [np.asarray(refined_cp, dtype=float), cp if reachable is None else cp[reachable]]
    )
    # Runner-up: far from the best, and not an equivalent of it (same CP: e.g. joint 1 of a
    # fixed base, or a joint turning about the tool axis, leaves every index unchanged).
    far = (np.max(np.abs(pool_q - best.q), axis=-1) > runner_up_separation) & (
        np.abs(pool_cp - best.cp) > EQUIVALENT_CP_RTOL * max(1.0, abs(best.cp))
    )
    runner_up = None
    if np.any(far):
        j = int(np.argmax(np.where(far, pool_cp, -np.inf)))
        c, i = exact(pool_q[j])
        runner_up = _candidate(pool_q[j], c, i)

    gain = best.cp - best_sample.cp
    logger.info("HCOM: best sample CP %.6g, refined %.6g (gain %.3g)", best_sample.cp, best.cp, gain)
    q.setflags(write=False)
    cp.setflags(write=False)
    if reachable is not None:
        reachable.setflags(write=False)
    return HaltConfiguration(
        best=best,
        best_sample=best_sample,
        runner_up=runner_up,
        refinement_gain=float(gain),
        ability=ability,
        samples=k,
        seed=seed,
        jacobian=jacobian,
        base="floating" if model_locked.floating else "fixed",
        joint_numbers=model_locked.joint_numbers,
        locked={lj.number: lj.angle for lj in model_locked.locked},
        lower=lo,
        upper=hi,
        characteristic_length=characteristic_length,
        reachability=reachability,
        q_samples=q,
        cp_samples=cp,
        indices_samples=ind,
        refine_evaluations=evaluations,
        reachable=reachable,
        reachable_samples=None if reachable is None else n_ok,
        k_range=k_range,
    )


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


def _unreachable_message(
    reach: HaltReachability,
    lo: FloatArray,
    hi: FloatArray,
    joint_numbers: tuple[int, ...],
    *,
    reason: str | None = None,
) -> str:
    t_min = reach.minimum_halt_time(lo, hi)
    which = "one k per joint" if reach.per_joint else "a shared k (000)"
    msg = (
        f"no halt configuration is reachable by the halt polynomial with {which} within "
        f"T = {reach.halt_time:g} s from {reach.describe_state()} (healthy joints {list(joint_numbers)})"
    )
    if reason is not None:
        msg += f": {reason} (bang-bang bound, necessary only)"
    if t_min is None:
        return msg + "; no halt time up to the search limit makes one reachable"
    return msg + f"; the smallest halt time with a reachable configuration is T = {t_min:.3f} s"


def evaluate_cp(result: HaltConfiguration, model_locked: ArmModel, q: ArrayLike) -> FloatArray:
    """CP (...) of configurations (..., n) [rad] on the frozen scale of a search result
    (same Jacobian, normalisation and weights), e.g. 000's printed ``q_best`` and ``q_sub``."""
    q = as_joint_array(model_locked, q)
    ind = configuration_indices(
        model_locked, q, jacobian=result.jacobian, characteristic_length=result.characteristic_length
    )
    return result.ability(ind)


# -- section plots (000 Fig. 7) ---------------------------------------------------------------


def section_figures(result: HaltConfiguration, *, bins: int = 72) -> list[Any]:
    """One matplotlib figure per healthy joint: joint angle [deg] vs CP over the sample set,
    with the upper envelope (max CP per angle bin), the best and the runner-up (000 Fig. 7).
    Under :class:`HaltReachability` unreachable samples are grey crosses (their own legend
    entry) and the envelope is over the reachable ones.

    Returns
    -------
    list of ``matplotlib.figure.Figure``, chain order.
    """
    from matplotlib.figure import Figure

    figures = []
    q_deg = np.degrees(result.q_samples)
    edges = np.linspace(
        math.degrees(float(result.lower.min())), math.degrees(float(result.upper.max())), bins + 1
    )
    for j, number in enumerate(result.joint_numbers):
        fig = Figure(figsize=(5.0, 3.4))
        ax = fig.add_subplot()
        ok = np.ones(result.samples, bool) if result.reachable is None else result.reachable
        if not ok.all():
            ax.scatter(
                q_deg[~ok, j],
                result.cp_samples[~ok],
                s=8.0,
                alpha=0.6,
                color="0.3",
                marker="x",
                linewidths=0.7,
                zorder=2.5,  # above the reachable cloud: a thin set must stay visible
                rasterized=True,
                label=f"unreachable samples ({int((~ok).sum())})",
            )
        ax.scatter(
            q_deg[ok, j],
            result.cp_samples[ok],
            s=1.5,
            alpha=0.25,
            color="tab:blue",
            rasterized=True,
            label="samples" if result.reachable is None else f"reachable samples ({int(ok.sum())})",
        )
        which = np.clip(np.digitize(q_deg[ok, j], edges) - 1, 0, bins - 1)
        envelope = np.full(bins, np.nan)
        np.fmax.at(envelope, which, result.cp_samples[ok])
        centres = 0.5 * (edges[1:] + edges[:-1])
        ax.plot(centres, envelope, color="tab:blue", lw=1.2, label="max CP per bin")
        ax.plot(math.degrees(result.best.q[j]), result.best.cp, "r*", ms=12, label="best")
        if result.runner_up is not None:
            ax.plot(math.degrees(result.runner_up.q[j]), result.runner_up.cp, "ks", ms=6, label="runner-up")
        ax.set_xlabel(f"angle of joint {number} [deg]")
        ax.set_ylabel("CP")
        ax.set_title(f"joint {number} - CP ({result.samples} samples)", fontsize=10)
        legend = ax.legend(fontsize=7, loc="lower right", markerscale=1.0)
        # the sample clouds are drawn faint and tiny: their legend keys opaque and readable
        for handle in getattr(legend, "legend_handles", getattr(legend, "legendHandles", [])):
            if hasattr(handle, "set_sizes"):
                handle.set_sizes([25.0])
                handle.set_alpha(1.0)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        figures.append(fig)
    return figures


def write_section_plots(result: HaltConfiguration, folder: str | Path, *, dpi: int = 110) -> list[Path]:
    """Write :func:`section_figures` as ``section_joint<N>.png`` in ``folder``; returns the paths."""
    from ..report import atomic_write_bytes, figure_png

    folder = Path(folder)
    paths = []
    for number, fig in zip(result.joint_numbers, section_figures(result)):
        path = folder / f"section_joint{number}.png"
        atomic_write_bytes(path, figure_png(fig, dpi=dpi))
        paths.append(path)
    return paths
