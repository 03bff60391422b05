"""The nominal straight-line path: trapezoidal velocity profile with parabolic blends (001 §4.3)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ScenarioError
from ...model import FloatArray

# -- Cartesian path -------------------------------------------------------------------------


@dataclass(frozen=True)
class CartesianPath:
    """Samples of the nominal straight-line path.

    Attributes
    ----------
    t
        (...) times [s].
    s, sd, sdd
        (...) path parameter in [0, 1] and its first two time derivatives [1/s, 1/s^2].
    x, xd, xdd
        (..., 3) position [m], velocity [m/s], acceleration [m/s^2].
    """

    t: FloatArray
    s: FloatArray
    sd: FloatArray
    sdd: FloatArray
    x: FloatArray
    xd: FloatArray
    xdd: FloatArray


def cartesian_trapezoid(
    x0: ArrayLike, dx: ArrayLike, t: ArrayLike, *, duration: float = 12.0, blend: float = 2.0
) -> CartesianPath:
    """Straight line with a trapezoidal velocity profile and parabolic blends (001 §4.3).

    ``s(t)``: constant acceleration ``a = v / t_b`` for ``t < t_b``, cruise at
    ``v = 1 / (T - t_b)`` and constant deceleration for ``t > T - t_b``; ``s(0) = 0``,
    ``s(T) = 1``, velocity zero at both ends, ``s`` and ``sd`` continuous.  Outside ``[0, T]``
    the path is held at its end points.

    Parameters
    ----------
    x0
        (3,) start position [m].
    dx
        (3,) displacement [m].
    t
        (...) times [s].
    duration, blend
        ``T`` and ``t_b`` [s], ``0 < 2 t_b <= T``.
    """
    if not (duration > 0 and 0 < blend <= duration / 2):
        raise ScenarioError(f"need 0 < blend <= duration/2; got blend={blend!r}, duration={duration!r}")
    times: FloatArray = np.clip(np.asarray(t, dtype=float), 0.0, duration)
    v = 1.0 / (duration - blend)
    a = v / blend
    rise = times < blend
    fall = times > duration - blend
    tau = duration - times
    s = np.where(rise, 0.5 * a * times**2, np.where(fall, 1.0 - 0.5 * a * tau**2, v * (times - 0.5 * blend)))
    sd = np.where(rise, a * times, np.where(fall, a * tau, v))
    sdd = np.where(rise, a, np.where(fall, -a, 0.0))
    x0 = np.asarray(x0, dtype=float)
    dx = np.asarray(dx, dtype=float)
    return CartesianPath(times, s, sd, sdd, x0 + s[..., None] * dx, sd[..., None] * dx, sdd[..., None] * dx)
