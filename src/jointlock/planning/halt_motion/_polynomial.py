"""The halt polynomial (000 eqs. 25-27): coefficients, profile, and the ``k``-part
``phi(t) = t^3 (t - T)^3``."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ScenarioError
from ...model import FloatArray


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
    return tuple(np.einsum("...jc,tc->...tj", c, p) for p in (powers, d1, d2))


def k_shape(t: ArrayLike, T: float | FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The ``k``-part of eq. 27, ``phi(t) = t^3 (t - T)^3``, and its first two derivatives,
    each (n_t,) [s^6, s^5, s^4] (or the broadcast shape of ``t`` and ``T``, several halt times
    at once)."""
    t = np.asarray(t, dtype=float)
    u = t - T
    phi = t**3 * u**3
    dphi = 3 * t**2 * u**2 * (t + u)
    ddphi = 6 * t * u * (t**2 + 3 * t * u + u**2)
    return phi, dphi, ddphi
