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

from ._common import _EPS, _jit, _nan_max, _nan_min
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
    not numpy's ``pow``; a division by ``phi`` as a multiplication by its inverse: within two
    ulps of the quotient), and each is widened by ``rtol`` of the terms it comes from (at
    least ``rtol`` of the bound itself), far above that round-off, so a halt time it calls
    infeasible is infeasible on the exact check too.

    ``halt_times`` (m,) [s]; ``picked`` (s,) int64 indices of the check times (of
    ``n_check``, spaced as ``np.linspace(0, T, n_check)``); ``q0, dq0, ddq0, qf`` (n,) the
    state at failure and the halt configuration; ``lo``, ``hi`` (3, n) the angle, rate and
    acceleration limits (infinite: none).
    """
    n = q0.shape[0]
    inf = np.inf
    # each kind's polynomial in t, k = 0 (000 eq. 27, halt_coefficients): (kind, power, joint)
    c = np.zeros((3, 6, n))
    ends = np.empty((3, n))
    for kind in range(3):
        for j in range(n):
            ends[kind, j] = max(abs(lo[kind, j]), abs(hi[kind, j]))
    for j in range(n):
        c[0, 0, j], c[0, 1, j], c[0, 2, j] = q0[j], dq0[j], ddq0[j] / 2.0
        c[1, 0, j], c[1, 1, j] = dq0[j], ddq0[j]
        c[2, 0, j] = ddq0[j]
    for m in range(halt_times.shape[0]):
        T = halt_times[m]
        T2 = T * T
        for j in range(n):
            h = qf[j] - q0[j]
            a3 = (20.0 * h - T2 * 3.0 * ddq0[j] - T * 12.0 * dq0[j]) / (2.0 * T2 * T)
            a4 = (T2 * 3.0 * ddq0[j] + T * 16.0 * dq0[j] - 30.0 * h) / (2.0 * T2 * T2)
            a5 = (-ddq0[j] * T2 - 6.0 * dq0[j] * T + 12.0 * h) / (2.0 * T2 * T2 * T)
            c[0, 3, j], c[0, 4, j], c[0, 5, j] = a3, a4, a5
            c[1, 2, j], c[1, 3, j], c[1, 4, j] = 3.0 * a3, 4.0 * a4, 5.0 * a5
            c[2, 1, j], c[2, 2, j], c[2, 3, j] = 6.0 * a3, 12.0 * a4, 20.0 * a5
        k_lo, k_hi = -inf, inf
        for p in range(picked.shape[0]):
            i = picked[p]
            t = T if i == n_check - 1 else i * (T / (n_check - 1))
            u = t - T
            t2, u2 = t * t, u * u
            t3, t4 = t2 * t, t2 * t2
            t5 = t4 * t
            shape = (t3 * u2 * u, 3.0 * t2 * u2 * (t + u), 6.0 * t * u * (t2 + 3.0 * t * u + u2))
            for kind in range(3):
                phi = shape[kind]
                if not abs(phi) > 0:  # no bound on k here
                    continue
                inverse = 1.0 / phi
                magnitude = abs(inverse)
                ck = c[kind]
                for j in range(n):
                    x0, x1, x2 = ck[0, j], ck[1, j] * t, ck[2, j] * t2
                    x3, x4, x5 = ck[3, j] * t3, ck[4, j] * t4, ck[5, j] * t5
                    base = x0 + x1 + x2 + x3 + x4 + x5
                    size = abs(x0) + abs(x1) + abs(x2) + abs(x3) + abs(x4) + abs(x5)
                    b1, b2 = (lo[kind, j] - base) * inverse, (hi[kind, j] - base) * inverse
                    if not math.isfinite(b1 + b2):  # an infinite limit (or NaN): no bound
                        continue
                    widen = rtol * (size + ends[kind, j]) * magnitude
                    k_lo = _nan_max(k_lo, _nan_min(b1, b2) - widen)
                    k_hi = _nan_min(k_hi, _nan_max(b1, b2) + widen)
        out[m] = k_lo > k_hi


@_jit
def _within(base, shape, lo, hi, scale, k_lo, k_hi, parent, count, child):
    """The limits of ``parent[:count]`` that can give the largest excess for some ``k`` in
    ``[k_lo, k_hi]`` into ``child``; returns how many (the test of
    ``jointlock.planning.halt_motion._feasibility._Limits.within``, which keeps every limit
    when a bound is not finite)."""
    inf = np.inf
    floor = -inf
    for c in range(count):
        i = parent[c]
        a, b = base[i] + k_lo * shape[i], base[i] + k_hi * shape[i]
        up = _nan_min((a - hi[i]) / scale[i], (b - hi[i]) / scale[i])
        down = _nan_min((lo[i] - a) / scale[i], (lo[i] - b) / scale[i])
        if up != up or down != down:
            floor = np.nan
            break
        floor = max(floor, up, down)
    if not math.isfinite(floor):
        for c in range(count):
            child[c] = parent[c]
        return count
    k_big = max(abs(k_lo), abs(k_hi))
    kept = 0
    for c in range(count):
        i = parent[c]
        a, b = base[i] + k_lo * shape[i], base[i] + k_hi * shape[i]
        up = _nan_max((a - hi[i]) / scale[i], (b - hi[i]) / scale[i])
        down = _nan_max((lo[i] - a) / scale[i], (lo[i] - b) / scale[i])
        lo_f = abs(lo[i]) if math.isfinite(lo[i]) else 0.0
        hi_f = abs(hi[i]) if math.isfinite(hi[i]) else 0.0
        terms = abs(base[i]) + k_big * abs(shape[i]) + max(lo_f, hi_f)
        margin = 1e-6 * (1.0 + abs(floor)) + 64 * _EPS * terms / scale[i]
        if not (up < floor - margin and down < floor - margin):
            child[kept] = i
            kept += 1
    return kept


@_jit
def least_violation_scan(base, shape, lo, hi, scale, grid, stretch, out):
    """The largest relative limit excess (0 when within every limit) of the halt at each
    ``k`` of ``grid`` (m,) [rad/s^6], ``out`` (m,): the scan of
    :func:`jointlock.planning.halt_motion.least_violating_k`, the same numbers bit for bit.

    The limits (L,) are the flat terms of ``_Limits`` (``traj = base + k shape`` against
    ``[lo, hi]``, an excess divided by ``scale``).  As the numpy route, the grid is halved
    down to stretches of at most ``stretch`` values, each half keeping only the limits of its
    parent that can still be the largest in it (:func:`_within`); a value is
    ``max(max((traj - hi), (lo - traj)) / scale over the kept limits, 0)``, the numpy route's
    operations, and a maximum is exact, so which limits are pruned cannot change it.
    """
    n_limits, m = base.shape[0], grid.shape[0]
    depth = 1
    size = m
    while size > stretch:
        size -= size // 2
        depth += 1
    kept = np.empty((depth + 1, max(n_limits, 1)), dtype=np.int64)
    counts = np.zeros(depth + 1, dtype=np.int64)
    for i in range(n_limits):
        kept[0, i] = i
    counts[0] = n_limits
    # depth-first over the halves: a node's kept limits are in row ``level``, its parent's
    # (which its sibling still needs) in the row above, untouched by the node's own subtree
    stack = np.empty((2 * depth + 2, 3), dtype=np.int64)
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, m, 0
    top = 1
    while top > 0:
        top -= 1
        start, stop, level = stack[top, 0], stack[top, 1], stack[top, 2]
        if level > 0:
            counts[level] = _within(
                base, shape, lo, hi, scale, grid[start], grid[stop - 1], kept[level - 1], counts[level - 1], kept[level]
            )
        if stop - start > stretch:
            middle = start + (stop - start) // 2
            stack[top, 0], stack[top, 1], stack[top, 2] = middle, stop, level + 1  # right, after the left
            stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = start, middle, level + 1
            top += 2
            continue
        row = kept[level]
        for g in range(start, stop):
            k = grid[g]
            worst = -np.inf
            for c in range(counts[level]):
                i = row[c]
                traj = base[i] + k * shape[i]
                worst = _nan_max(worst, _nan_max(traj - hi[i], lo[i] - traj) / scale[i])
            out[g] = _nan_max(worst, 0.0)
