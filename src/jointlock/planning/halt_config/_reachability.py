"""Exact reachability of a halt configuration by 000's halt polynomial (eq. 27) under the
angle, speed and acceleration limits: :class:`HaltReachability`."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from ..._search1d import bisect_boundary
from ...errors import ConfigurationError, InfeasibleError
from ...model import ArmModel, FloatArray
from ..halt_motion import LIMIT_RTOL, AffineKBounds, KIntervalBatch
from ._bound import ReachabilityBound, _readonly


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
        # looked up on the package, so that ``jointlock.planning.halt_config.AffineKBounds``
        # stays the one name to patch (as when this was one module)
        from .. import halt_config

        return halt_config.AffineKBounds(
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
                return float(bisect_boundary(lambda x: ok(float(x)), prev, t, xtol=tol).true_end)
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
