"""000's halt objective (eq. 32) for a batch of candidate ``k``, compiled: each candidate's halt
(eq. 27) sampled and the norm of its base torque by the Newton-Euler kernels of
:mod:`jointlock._kernels._dynamics`, in one call (:func:`base_moment_norms`); the caller
takes the time average (Simpson's rule, the same ``values @ weights`` as the numpy route).

Why next to :func:`~jointlock._kernels._dynamics.rnea_fixed`.  The objective's numpy route
materialises every candidate's ``q, dq, ddq`` (the scan's 401 candidates x 501 samples x 6
joints x 3: 29 MB, in chunks of 60,000 samples) and the torques, wrench, acceleration and
twist of every sample, then takes
the norm and Simpson's sum; at a campaign's batch sizes that costs as much as the Newton-Euler
pass itself, and a single candidate (the bounded search after the scan) pays ~0.8 ms of calls
for 0.1 ms of arithmetic.  Here the samples are made a chunk at a time, exactly as
:meth:`jointlock.planning.halt_motion.HaltProblem.trajectory` makes them (``base + k phi``,
the same two operations), so every sample's torque, and its norm, is the kernels' to the bit.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import _jit, _nan_max, _nan_min
from ._dynamics import rnea_fixed, rnea_floating

#: Samples per Newton-Euler call: the work arrays of a chunk stay in L2.
CHUNK = 4096


@_jit
def base_moment_norms(
    base_q, base_dq, base_ddq, phi, dphi, ddphi, k, floating,
    rot, pos, mass, com, inertia, root, base_acc, point, out,
):  # fmt: skip
    """The base moment's norm ``out[c, t] = ||n_d(t; k_c)||`` [N m] of every candidate's halt.

    Parameters
    ----------
    base_q, base_dq, base_ddq : (n_t, n) the ``k = 0`` part of the halt [rad, rad/s, rad/s^2].
    phi, dphi, ddphi : (n_t,) the ``k`` part ``t^3 (t - T)^3`` and its derivatives.
    k : (n_c, n) each candidate's ``k`` of every joint [rad/s^6].
    floating : True: the free-floating kernel (``root``, the spacecraft); False: the fixed one
        (``base_acc``).
    rot, pos, mass, com, inertia, root, base_acc, point : as :func:`rnea_floating` /
        :func:`rnea_fixed` take them.
    out : (n_c, n_t) written.

    Returns
    -------
    Number of samples whose system inertia is not positive definite (free-floating; their
    norms are meaningless), as :func:`rnea_floating`.
    """
    n_t, n = base_q.shape
    n_c = k.shape[0]
    total = n_c * n_t
    bad = 0
    for s0 in range(0, total, CHUNK):
        m = min(CHUNK, total - s0)
        q, dq, ddq = np.empty((m, n)), np.empty((m, n)), np.empty((m, n))
        for s in range(m):
            c, t = divmod(s0 + s, n_t)
            for i in range(n):
                kc = k[c, i]
                q[s, i] = base_q[t, i] + kc * phi[t]
                dq[s, i] = base_dq[t, i] + kc * dphi[t]
                ddq[s, i] = base_ddq[t, i] + kc * ddphi[t]
        tau, wrench = np.empty((m, n)), np.empty((m, 6))
        if floating:
            acc, twist = np.empty((m, 6)), np.empty((m, 6))
            bad += rnea_floating(q, dq, ddq, rot, pos, mass, com, inertia, root, point, tau, wrench, acc, twist)
        else:
            rnea_fixed(q, dq, ddq, rot, pos, mass, com, inertia, base_acc, point, tau, wrench)
        for s in range(m):
            c, t = divmod(s0 + s, n_t)
            x, y, z = wrench[s, 3], wrench[s, 4], wrench[s, 5]
            out[c, t] = math.sqrt(x * x + y * y + z * z)  # np.linalg.norm's sum, in its order
    return bad


@_jit
def k_intervals(base, shape, lo, hi, lo_slack, hi_slack, out):
    """Each joint's feasible interval of ``k`` on the check grid, ``out`` (n, 2) [rad/s^6]: the
    numbers of :func:`jointlock.planning.halt_motion.feasible_k_intervals` (the same
    divisions, and maxima and minima, which are exact), without its 15 arrays of
    ``3 x n_t x n``.

    ``base`` (3, n_t, n): the ``k = 0`` angle, rate and acceleration; ``shape`` (3, n_t): the
    ``k`` part and its derivatives; ``lo``, ``hi`` (3, n): the limits; ``lo_slack``,
    ``hi_slack`` (3, n): the limits widened by the round-off slack (where the ``k`` part
    vanishes, the value must already be within them).
    """
    n_t, n = base.shape[1], base.shape[2]
    inf = np.inf
    for j in range(n):
        k_min, k_max = -inf, inf
        for kind in range(3):
            lo_j, hi_j = lo[kind, j], hi[kind, j]
            lo_s, hi_s = lo_slack[kind, j], hi_slack[kind, j]
            for t in range(n_t):
                s = shape[kind, t]
                b = base[kind, t, j]
                if abs(s) > 0:
                    b1, b2 = (lo_j - b) / s, (hi_j - b) / s
                    low, high = _nan_min(b1, b2), _nan_max(b1, b2)
                elif b < lo_s or b > hi_s:
                    low, high = inf, -inf
                else:
                    low, high = -inf, inf
                k_min, k_max = _nan_max(k_min, low), _nan_min(k_max, high)
        out[j, 0], out[j, 1] = k_min, k_max


@_jit
def screen_k_bounds(halt_times, picked, n_check, q0, dq0, ddq0, qf, lo, hi, rtol, out):
    """For each halt time, whether no shared ``k`` keeps the limits at the check times
    ``picked`` alone, ``out`` (m,) bool: the screen of
    :func:`jointlock.planning.halt_motion.minimum_halt_time`, whose numpy route
    (``_surely_infeasible``) makes ~60 arrays of ``m x picked x n`` for what is a few
    operations per sample.

    Only a screen: its bounds are the numpy route's up to round-off (powers by multiplication,
    not numpy's ``pow``), and each is widened by ``rtol`` of the terms it comes from, far above
    that round-off, so a halt time it calls infeasible is infeasible on the exact check too.

    ``halt_times`` (m,) [s]; ``picked`` (s,) int64 indices of the check times (of
    ``n_check``, spaced as ``np.linspace(0, T, n_check)``); ``q0, dq0, ddq0, qf`` (n,) the
    state at failure and the halt configuration; ``lo``, ``hi`` (3, n) the angle, rate and
    acceleration limits (infinite: none).
    """
    n = q0.shape[0]
    inf = np.inf
    for m in range(halt_times.shape[0]):
        T = halt_times[m]
        T2 = T * T
        k_lo, k_hi = -inf, inf
        for p in range(picked.shape[0]):
            i = picked[p]
            t = T if i == n_check - 1 else i * (T / (n_check - 1))
            u = t - T
            t2, u2 = t * t, u * u
            shape = (t2 * t * u2 * u, 3.0 * t2 * u2 * (t + u), 6.0 * t * u * (t2 + 3.0 * t * u + u2))
            for j in range(n):
                h = qf[j] - q0[j]
                a3 = (20.0 * h - T2 * 3.0 * ddq0[j] - T * 12.0 * dq0[j]) / (2.0 * T2 * T)
                a4 = (T2 * 3.0 * ddq0[j] + T * 16.0 * dq0[j] - 30.0 * h) / (2.0 * T2 * T2)
                a5 = (-ddq0[j] * T2 - 6.0 * dq0[j] * T + 12.0 * h) / (2.0 * T2 * T2 * T)
                for kind in range(3):
                    if kind == 0:
                        terms = (q0[j], dq0[j] * t, ddq0[j] / 2.0 * t2, a3 * t2 * t, a4 * t2 * t2, a5 * t2 * t2 * t)
                    elif kind == 1:
                        terms = (dq0[j], ddq0[j] * t, 3.0 * a3 * t2, 4.0 * a4 * t2 * t, 5.0 * a5 * t2 * t2, 0.0)
                    else:
                        terms = (ddq0[j], 6.0 * a3 * t, 12.0 * a4 * t2, 20.0 * a5 * t2 * t, 0.0, 0.0)
                    base, size = 0.0, 0.0
                    for x in terms:
                        base += x
                        size += abs(x)
                    phi = shape[kind]
                    if not abs(phi) > 0:
                        continue
                    low_limit, high_limit = lo[kind, j], hi[kind, j]
                    b1, b2 = (low_limit - base) / phi, (high_limit - base) / phi
                    if not math.isfinite(b1 + b2):  # an infinite limit (or NaN): no bound
                        continue
                    ends = max(abs(low_limit), abs(high_limit))
                    widen = rtol * (size + ends) / abs(phi)
                    k_lo = _nan_max(k_lo, _nan_min(b1, b2) - widen)
                    k_hi = _nan_min(k_hi, _nan_max(b1, b2) + widen)
        out[m] = k_lo > k_hi
