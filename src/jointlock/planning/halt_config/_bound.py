"""The bang-bang reachability bound (necessary only): where each healthy joint can come to
rest within a halt time under speed and acceleration limits."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ConfigurationError, InfeasibleError
from ...model import FloatArray


def _readonly(a: ArrayLike) -> FloatArray:
    out = np.array(a, dtype=float)
    out.setflags(write=False)
    return out


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
